// Velocity commands in time (core/control/cmd_vel_input.h): a command acts from its stamp, a stale one
// ramps the robot to a stop through the limiter, refused commands change nothing, and lockstep's pairing
// knows when the output at t can no longer change.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "sowing_robot/core/control/cmd_vel_input.h"

namespace sowing_robot {
namespace core {
namespace {

constexpr std::int64_t kPeriod = 1000000;  // 1 ms [ns]
constexpr std::int64_t ms(double milliseconds) { return static_cast<std::int64_t>(milliseconds * 1e6); }

/// The output at every period from 0 to `until` (inclusive).
std::vector<VelocityCommand> runTo(CmdVelInput& in, std::int64_t until) {
  std::vector<VelocityCommand> out;
  for (std::int64_t t = 0; t <= until; t += kPeriod) out.push_back(in.update(t));
  return out;
}

void expectSame(const std::vector<VelocityCommand>& a, const std::vector<VelocityCommand>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].v, b[k].v) << k;
    ASSERT_EQ(a[k].omega, b[k].omega) << k;
    ASSERT_EQ(a[k].v_dot, b[k].v_dot) << k;
    ASSERT_EQ(a[k].omega_dot, b[k].omega_dot) << k;
  }
}

TEST(CmdVelInput, ParametersAndTheirRanges) {
  const CmdVelParams p;
  EXPECT_DOUBLE_EQ(p.timeout, 0.5);
  EXPECT_EQ(p.validate(), "");
  ASSERT_NE(CmdVelParams::table().find("linear/max_jerk"), nullptr);
  CmdVelParams bad;
  bad.timeout = -0.1;
  EXPECT_NE(bad.validate().find("cmd_vel_timeout"), std::string::npos) << bad.validate();
  EXPECT_THROW(CmdVelInput(bad, true), std::invalid_argument);
}

TEST(CmdVelInput, ACommandActsFromItsStampThroughTheLimiter) {
  // Stamped between two periods (2.5 ms): the limiter switches target exactly there.
  CmdVelInput in(CmdVelParams(), true);
  ASSERT_EQ(in.offer(ms(2.5), 0.3, 0.2), CmdVerdict::accepted);
  const auto out = runTo(in, ms(10));
  VelocityLimiter ref{VelocityLimits()};
  EXPECT_EQ(out[2].v, 0.0);
  ref.advance(0.3, 0.2, secondsFromNanos(ms(3) - ms(2.5)));  // at rest until 2.5 ms, then 2.5 -> 3 ms
  EXPECT_EQ(out[3].v, ref.command().v);
  EXPECT_EQ(out[3].omega_dot, ref.command().omega_dot);
  EXPECT_GT(out[3].v, 0.0);
  EXPECT_GT(out[10].v, out[3].v);
  EXPECT_FALSE(in.stale());
}

TEST(CmdVelInput, AStaleCommandRampsToAStopAfterTheTimeout) {
  CmdVelParams p;
  p.timeout = 0.5;
  CmdVelInput in(p, true);
  ASSERT_EQ(in.offer(0, 0.3, 0.2), CmdVerdict::accepted);
  const auto out = runTo(in, ms(4000));
  // Up to the timeout the command's own profile (a limiter given 0.3, 0.2 throughout) ...
  VelocityLimiter ref{p.limits};
  for (int k = 1; k <= 500; ++k) {
    ref.advance(0.3, 0.2, secondsFromNanos(kPeriod));  // as the input steps: on the ns grid
    ASSERT_EQ(out[k].v, ref.command().v) << k;
    ASSERT_EQ(out[k].omega, ref.command().omega) << k;
  }
  EXPECT_NEAR(out[500].omega, 0.2, 1e-12);  // reached (0.45 s)
  EXPECT_LT(out[500].v, 0.3);               // still rising (0.85 s)
  // ... then towards zero from the state at 0.5 s, reaching it when the profile says and staying there.
  const AxisState v500{out[500].v, out[500].v_dot}, w500{out[500].omega, out[500].omega_dot};
  const double stop_v = planProfile(v500, 0.0, p.limits.linear()).duration();
  const double stop_w = planProfile(w500, 0.0, p.limits.angular()).duration();
  EXPECT_GT(out[501].v_dot, -1e-12);  // no step in the acceleration: it falls at the jerk bound
  EXPECT_LT(out[501].v_dot, out[500].v_dot);
  // (to rounding: one period before the end the profile is still J dt^3 / 6 ~ 3e-10 away)
  const auto stopped = [&](std::size_t k) { return std::abs(out[k].v) <= 1e-12 && std::abs(out[k].omega) <= 1e-12; };
  const std::size_t k_stop = 500 + static_cast<std::size_t>(std::ceil(std::max(stop_v, stop_w) / 1e-3 - 1e-6));
  EXPECT_FALSE(stopped(k_stop - 1));
  for (std::size_t k = k_stop; k < out.size(); ++k) ASSERT_TRUE(stopped(k)) << k;
  EXPECT_EQ(out.back().v, 0.0);  // exactly, once the profile has ended
  EXPECT_TRUE(in.stale());
  EXPECT_NEAR(in.age(), 4.0, 1e-12);
  // A fresh command drives again.
  ASSERT_EQ(in.offer(ms(4000), 0.1, 0.0), CmdVerdict::accepted);
  EXPECT_GT(in.update(ms(4100)).v, 0.0);
  EXPECT_FALSE(in.stale());
}

TEST(CmdVelInput, ZeroTimeoutKeepsACommandForever) {
  CmdVelParams p;
  p.timeout = 0.0;
  CmdVelInput in(p, true);
  in.offer(0, -0.3, 0.0);
  EXPECT_EQ(runTo(in, ms(20000)).back().v, -0.3);
  EXPECT_FALSE(in.stale());
}

TEST(CmdVelInput, RefusedCommandsChangeNothing) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  CmdVelInput clean(CmdVelParams(), true), noisy(CmdVelParams(), true);
  for (CmdVelInput* in : {&clean, &noisy}) {
    const bool bad = in == &noisy;
    if (bad) {
      EXPECT_EQ(in->offer(ms(50), nan, 0.1), CmdVerdict::non_finite);
    }
    EXPECT_EQ(in->offer(ms(100), 0.3, 0.2), CmdVerdict::accepted);
    if (bad) {
      EXPECT_EQ(in->offer(ms(300), 0.2, inf), CmdVerdict::non_finite);
      EXPECT_EQ(in->offer(ms(350), 1.5, 0.0), CmdVerdict::out_of_range);    // |v| > 1 m/s
      EXPECT_EQ(in->offer(ms(360), 0.0, -1.01), CmdVerdict::out_of_range);  // |omega| > 1 rad/s
      EXPECT_EQ(in->offer(ms(50), 0.1, 0.0), CmdVerdict::out_of_order);     // before the one at 100 ms
    }
    EXPECT_EQ(in->offer(ms(400), -0.2, 0.1), CmdVerdict::accepted);
    // The refused ones neither keep a command fresh nor move lockstep's pairing on.
    if (bad) {
      EXPECT_EQ(in->offer(ms(2000), nan, nan), CmdVerdict::non_finite);
    }
    EXPECT_FALSE(in->knownUntil(ms(401)));
  }
  expectSame(runTo(clean, ms(3000)), runTo(noisy, ms(3000)));
}

TEST(CmdVelInput, LockstepPairingAndLateCommands) {
  CmdVelInput strict(CmdVelParams(), true);
  EXPECT_FALSE(strict.knownUntil(0));
  strict.offer(ms(5), 0.1, 0.0);
  EXPECT_TRUE(strict.knownUntil(ms(5)));  // the output at 5 ms needs the commands stamped before 5 ms
  EXPECT_FALSE(strict.knownUntil(ms(6)));
  strict.update(0);
  strict.update(ms(5));
  EXPECT_EQ(strict.offer(ms(5), 0.2, 0.0), CmdVerdict::accepted);  // acts from 5 ms: not late
  CmdVelInput fresh(CmdVelParams(), true);
  fresh.update(ms(10));
  EXPECT_EQ(fresh.offer(ms(9), 0.1, 0.0), CmdVerdict::late);  // strict: the past cannot change
  // Realtime: a command stamped in the past acts from now on, dated by its stamp for the timeout.
  CmdVelInput lenient(CmdVelParams(), false);
  lenient.update(0);
  lenient.update(ms(100));
  EXPECT_EQ(lenient.offer(ms(90), 0.3, 0.0), CmdVerdict::accepted);
  EXPECT_EQ(lenient.command().v, 0.0);
  EXPECT_GT(lenient.update(ms(101)).v, 0.0);
  lenient.update(ms(589));
  EXPECT_FALSE(lenient.stale());
  lenient.update(ms(590));
  EXPECT_TRUE(lenient.stale());  // 0.5 s after its stamp, 90 ms
}

TEST(CmdVelInput, UpdatesOfAnyLengthGiveTheSameOutput) {
  // The pieces between command stamps are exact profiles, so a realtime node that missed states (longer
  // steps) hands out what a 1 ms one does at the same instants, up to rounding.
  CmdVelInput fine(CmdVelParams(), true), coarse(CmdVelParams(), true);
  for (CmdVelInput* in : {&fine, &coarse}) {
    in->offer(ms(0), 0.5, -0.4);
    in->offer(ms(733.3), -0.2, 0.3);
    in->offer(ms(1500), 0.0, 0.0);
  }
  const auto f = runTo(fine, ms(3000));
  for (std::int64_t t = 0; t <= ms(3000); t += 20 * kPeriod) {
    const VelocityCommand c = coarse.update(t);
    ASSERT_NEAR(c.v, f[t / kPeriod].v, 1e-12) << t;
    ASSERT_NEAR(c.omega_dot, f[t / kPeriod].omega_dot, 1e-12) << t;
  }
}

}  // namespace
}  // namespace core
}  // namespace sowing_robot
