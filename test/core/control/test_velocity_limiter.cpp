// The velocity limiter of velocity mode (core/control/velocity_limiter.h): bounds on value, acceleration
// and jerk, forward and in reverse; the time-optimal reach time; accelerations that are the derivatives of
// the velocities handed out, whatever the step length.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "sowing_robot/core/control/velocity_limiter.h"

namespace sowing_robot {
namespace core {
namespace {

constexpr double kDt = 1e-3;  // the control period of the runs [s]

/// Closed form of the time from rest to `dv` at full jerk and acceleration: a trapezoid of acceleration
/// when the peak reaches max_acceleration, a triangle otherwise.
double reachTimeFromRest(double dv, const AxisLimits& l) {
  dv = std::abs(dv);
  const double a = l.max_acceleration, j = l.max_jerk;
  return dv >= a * a / j ? dv / a + a / j : 2.0 * std::sqrt(dv / j);
}

struct Trace {
  std::vector<double> v, a;  // one sample per period, from t = 0
};

/// One axis stepped at kDt towards `target` for `seconds`, from `start`.
Trace runAxis(AxisState start, double target, const AxisLimits& l, double seconds) {
  Trace tr;
  AxisState s = start;
  for (int k = 0; k * kDt <= seconds; ++k) {
    tr.v.push_back(s.value);
    tr.a.push_back(s.acceleration);
    s = planProfile(s, target, l).at(s, kDt);
  }
  return tr;
}

/// Every sample within the bounds (a small rounding allowance), the jerk from one sample to the next too.
void expectWithinBounds(const Trace& tr, const AxisLimits& l) {
  const double tol = 1e-9;
  for (std::size_t k = 0; k < tr.v.size(); ++k) {
    ASSERT_LE(std::abs(tr.v[k]), l.max_velocity + tol) << "sample " << k;
    ASSERT_LE(std::abs(tr.a[k]), l.max_acceleration + tol) << "sample " << k;
    if (k > 0) {
      ASSERT_LE(std::abs(tr.a[k] - tr.a[k - 1]), l.max_jerk * kDt + tol) << "sample " << k;
    }
  }
}

/// First sample index from which the trace stays at `target` (to rounding: one period before the end of a
/// profile it is still J dt^3 / 6 ~ 3e-10 away).
std::size_t settledFrom(const Trace& tr, double target) {
  std::size_t k = tr.v.size();
  while (k > 0 && std::abs(tr.v[k - 1] - target) <= 1e-12 && std::abs(tr.a[k - 1]) <= 1e-9) --k;
  return k;
}

/// The first period at or after `seconds`.
std::size_t periodsUpTo(double seconds) { return static_cast<std::size_t>(std::ceil(seconds / kDt - 1e-6)); }

const VelocityLimits kLimits;  // the defaults: linear 1 m/s, 0.5 m/s^2, 2 m/s^3; angular 1, 1, 4

TEST(VelocityLimiter, DefaultsAndRefusedLimits) {
  EXPECT_EQ(kLimits.validate(), "");
  EXPECT_DOUBLE_EQ(kLimits.v_max, 1.0);
  EXPECT_DOUBLE_EQ(kLimits.v_acceleration, 0.5);
  EXPECT_DOUBLE_EQ(kLimits.v_jerk, 2.0);
  VelocityLimits bad;
  bad.omega_jerk = 0.0;
  EXPECT_NE(bad.validate().find("angular/max_jerk"), std::string::npos) << bad.validate();
  EXPECT_THROW(VelocityLimiter{bad}, std::invalid_argument);
}

TEST(VelocityLimiter, StepReachesTheTargetAtTheTimeOptimalTimeWithinEveryBound) {
  // 0.3 m/s: a trapezoid of acceleration (0.3 >= 0.5^2 / 2); 0.2 rad/s: a triangle (0.2 < 1 / 4).
  for (const auto& [target, l] : {std::pair<double, AxisLimits>{0.3, kLimits.linear()}, {0.2, kLimits.angular()}}) {
    const double t_reach = reachTimeFromRest(target, l);
    EXPECT_NEAR(planProfile({}, target, l).duration(), t_reach, 1e-12);
    const Trace tr = runAxis({}, target, l, t_reach + 1.0);
    expectWithinBounds(tr, l);
    // Settled exactly from the first period at or after the reach time, and not one period before.
    EXPECT_EQ(settledFrom(tr, target), periodsUpTo(t_reach));
    for (double v : tr.v) EXPECT_LE(v, target + 1e-12);  // no overshoot
  }
  // The trapezoid really reaches the acceleration bound, the triangle stays below its own.
  const Trace lin = runAxis({}, 0.3, kLimits.linear(), 1.0);
  EXPECT_NEAR(*std::max_element(lin.a.begin(), lin.a.end()), 0.5, 1e-12);
  const Trace ang = runAxis({}, 0.2, kLimits.angular(), 1.0);
  EXPECT_LT(*std::max_element(ang.a.begin(), ang.a.end()), 0.95);
}

TEST(VelocityLimiter, ReverseMirrorsForwardAndHonoursTheBounds) {
  const AxisLimits l = kLimits.linear();
  const Trace fwd = runAxis({}, 0.3, l, 2.0), rev = runAxis({}, -0.3, l, 2.0);
  ASSERT_EQ(fwd.v.size(), rev.v.size());
  for (std::size_t k = 0; k < fwd.v.size(); ++k) {
    EXPECT_EQ(rev.v[k], -fwd.v[k]) << k;
    EXPECT_EQ(rev.a[k], -fwd.a[k]) << k;
  }
  // Full speed ahead to full speed astern: through zero, within every bound, in the time of the whole
  // 2 m/s change, and never past -max_velocity.
  const Trace flip = runAxis({0.8, 0.0}, -0.8, l, 6.0);
  expectWithinBounds(flip, l);
  EXPECT_EQ(settledFrom(flip, -0.8), periodsUpTo(reachTimeFromRest(1.6, l)));
  // A target beyond the bound is held at the bound.
  VelocityLimiter limiter(kLimits);
  for (int k = 0; k < 10000; ++k) limiter.advance(-5.0, 5.0, kDt);
  EXPECT_EQ(limiter.command().v, -1.0);
  EXPECT_EQ(limiter.command().omega, 1.0);
}

TEST(VelocityLimiter, JerkBoundsTheAccelerationChangeWhenTheTargetMovesMidRamp) {
  // Rising at full acceleration towards 0.9, the target drops to 0.2 (already within reach of the jerk:
  // an overshoot cannot be avoided), then jumps to -0.6: the acceleration turns at the jerk bound only.
  const AxisLimits l = kLimits.linear();
  AxisState s;
  Trace tr;
  for (int k = 0; k < 6000; ++k) {
    const double target = k < 700 ? 0.9 : k < 2500 ? 0.2 : -0.6;
    tr.v.push_back(s.value);
    tr.a.push_back(s.acceleration);
    s = planProfile(s, target, l).at(s, kDt);
  }
  expectWithinBounds(tr, l);
  EXPECT_NEAR(tr.a[699], 0.5, 1e-12);  // at full acceleration when the target moved
  EXPECT_EQ(tr.v.back(), -0.6);
  // With a target the jerk can still reach, there is no overshoot: the value never passes 0.9.
  const Trace clean = runAxis({0.2, 0.3}, 0.9, l, 4.0);
  for (double v : clean.v) EXPECT_LE(v, 0.9 + 1e-12);
}

TEST(VelocityLimiter, AccelerationsAreTheDerivativesOfTheVelocities) {
  // The profile is analytic: one step of 10 ms lands where ten steps of 1 ms do (re-planning from a point
  // of the profile gives the rest of the same profile), and over each step the velocity changes by the
  // integral of the acceleration handed out (trapezoid rule, exact up to the jerk's kinks).
  const AxisLimits l = kLimits.linear();
  for (double target : {0.3, -0.7, 0.05}) {
    AxisState coarse, fine;
    for (int k = 0; k < 300; ++k) {
      coarse = planProfile(coarse, target, l).at(coarse, 10 * kDt);
      for (int i = 0; i < 10; ++i) fine = planProfile(fine, target, l).at(fine, kDt);
      ASSERT_NEAR(coarse.value, fine.value, 1e-12) << "target " << target << ", step " << k;
      ASSERT_NEAR(coarse.acceleration, fine.acceleration, 1e-12) << "target " << target << ", step " << k;
    }
    const Trace tr = runAxis({}, target, l, 3.0);
    for (std::size_t k = 0; k + 1 < tr.v.size(); ++k) {
      const double slope = (tr.v[k + 1] - tr.v[k]) / kDt, mean_a = 0.5 * (tr.a[k] + tr.a[k + 1]);
      // a is piecewise linear with slopes within +-J: the trapezoid rule is off by at most J dt / 4.
      ASSERT_NEAR(slope, mean_a, l.max_jerk * kDt / 4 + 1e-9) << "target " << target << ", step " << k;
    }
  }
  // Both axes at once through the class: v_dot and omega_dot are the state's accelerations.
  VelocityLimiter limiter(kLimits);
  limiter.advance(0.3, -0.2, 0.05);
  const AxisState v = planProfile({}, 0.3, kLimits.linear()).at({}, 0.05);
  const AxisState w = planProfile({}, -0.2, kLimits.angular()).at({}, 0.05);
  EXPECT_EQ(limiter.command().v, v.value);
  EXPECT_EQ(limiter.command().v_dot, v.acceleration);
  EXPECT_EQ(limiter.command().omega, w.value);
  EXPECT_EQ(limiter.command().omega_dot, w.acceleration);
  EXPECT_NEAR(v.acceleration, 2.0 * 0.05, 1e-12);  // the first 50 ms at full jerk
}

}  // namespace
}  // namespace core
}  // namespace sowing_robot
