// The outer loop's output limits (core/control/command_limits.h): off, the command passes to the bit; on, v and
// omega stay within their bounds, change by at most max_acceleration dt per period with the accelerations handed
// on being the limited command's, and a command within every bound passes with the controller's own derivatives;
// a hold passes and restarts the slew from rest; bad parameters are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "sowing_robot/core/control/command_limits.h"

using namespace sowing_robot::core;

namespace {
CommandLimitsParams on() {
  CommandLimitsParams p;
  p.enabled = true;
  p.max_v = 1.5;
  p.max_omega = 2.0;
  p.max_acceleration = 0.5;
  p.max_angular_accel = 3.0;
  return p;
}
VelocityCommand command(double v, double omega, double v_dot = 0.0, double omega_dot = 0.0) {
  VelocityCommand c;
  c.v = v;
  c.omega = omega;
  c.v_dot = v_dot;
  c.omega_dot = omega_dot;
  return c;
}
constexpr double kDt = 0.001;
}  // namespace

TEST(CommandLimits, OffTheCommandPasses) {
  CommandLimiter off{CommandLimitsParams{}};
  const VelocityCommand c = command(4.5, -3.3, 20.0, -7.0);
  const VelocityCommand out = off.limit(c, kDt);
  EXPECT_EQ(out.v, c.v);
  EXPECT_EQ(out.omega, c.omega);
  EXPECT_EQ(out.v_dot, c.v_dot);
  EXPECT_EQ(out.omega_dot, c.omega_dot);
  EXPECT_FALSE(off.limiting());
}

TEST(CommandLimits, AStepIsSlewedToItsBound) {
  const CommandLimitsParams p = on();
  CommandLimiter lim(p);
  double last_v = 0.0, last_omega = 0.0;
  for (int k = 1; k <= 6000; ++k) {  // 6 s of a step to 4.5 m/s and -3.3 rad/s
    const VelocityCommand out = lim.limit(command(4.5, -3.3), kDt);
    EXPECT_LE(std::fabs(out.v), p.max_v);
    EXPECT_LE(std::fabs(out.omega), p.max_omega);
    EXPECT_LE(std::fabs(out.v - last_v), p.max_acceleration * kDt * (1 + 1e-12));
    EXPECT_LE(std::fabs(out.omega - last_omega), p.max_angular_accel * kDt * (1 + 1e-12));
    EXPECT_NEAR(out.v_dot, (out.v - last_v) / kDt, 1e-9);  // the limited command's own derivative
    EXPECT_NEAR(out.omega_dot, (out.omega - last_omega) / kDt, 1e-9);
    EXPECT_TRUE(lim.limiting());
    if (k == 1000) EXPECT_NEAR(out.v, 0.5, 1e-9);  // 1 s at 0.5 m/s^2
    last_v = out.v;
    last_omega = out.omega;
  }
  EXPECT_EQ(last_v, p.max_v);
  EXPECT_EQ(last_omega, -p.max_omega);
}

TEST(CommandLimits, ACommandWithinTheBoundsPassesWithItsDerivatives) {
  CommandLimiter lim(on());
  // A ramp at 0.2 m/s^2 and 1 rad/s^2 (within the bounds) from rest: passed as the controller gave it.
  for (int k = 1; k <= 1000; ++k) {
    const double t = k * kDt;
    const VelocityCommand c = command(0.2 * t, 1.0 * t, 0.2, 1.0);
    const VelocityCommand out = lim.limit(c, kDt);
    EXPECT_EQ(out.v, c.v);
    EXPECT_EQ(out.omega, c.omega);
    EXPECT_EQ(out.v_dot, 0.2);
    EXPECT_EQ(out.omega_dot, 1.0);
    EXPECT_FALSE(lim.limiting());
  }
}

TEST(CommandLimits, AHoldPassesAndRestartsFromRest) {
  CommandLimiter lim(on());
  for (int k = 0; k < 3000; ++k) lim.limit(command(1.0, 0.0), kDt);  // at 1 m/s
  const VelocityCommand hold = lim.limit(holdCommand(), kDt);
  EXPECT_TRUE(hold.hold);
  EXPECT_EQ(hold.v, 0.0);
  const VelocityCommand after = lim.limit(command(1.0, 0.0), kDt);
  EXPECT_NEAR(after.v, 0.5 * kDt, 1e-15);  // from rest again
}

TEST(CommandLimits, ANonFiniteCommandPassesAndLeavesTheState) {
  CommandLimiter lim(on());
  lim.limit(command(1.0, 0.0), kDt);
  const VelocityCommand bad = lim.limit(command(std::numeric_limits<double>::quiet_NaN(), 0.0), kDt);
  EXPECT_TRUE(std::isnan(bad.v));  // the inner loop's to refuse, as without the limits
  EXPECT_NEAR(lim.limit(command(1.0, 0.0), kDt).v, 2 * 0.5 * kDt, 1e-15);
}

TEST(CommandLimits, BadParametersAreRefused) {
  CommandLimitsParams p = on();
  p.max_acceleration = 0.0;
  EXPECT_NE(p.validate().find("limits/max_acceleration"), std::string::npos);
  EXPECT_THROW(CommandLimiter{p}, std::invalid_argument);
  p = on();
  p.max_v = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(CommandLimiter{p}, std::invalid_argument);
}
