// The speed governor (core/planning/speed_governor.h): off it is the wrapped reference; on, the target
// keeps to its path at a rate that falls while the wheels slip and rises back once they grip.
#include <gtest/gtest.h>

#include <cmath>

#include "sowing_robot/core/planning/speed_governor.h"

using namespace sowing_robot::core;

TEST(SpeedGovernor, OffItIsTheReference) {
  LineReference line(1.0, 3.0), same(1.0, 3.0);
  GovernedReference g(line, SpeedGovernorParams{});
  g.reset();
  same.reset();
  for (int k = 0; k < 100; ++k) {
    g.report(true, 0.01);
    const Reference a = g.next(0.01 * k), b = same.next(0.01 * k);
    EXPECT_EQ(a.pose.x, b.pose.x);
    EXPECT_EQ(a.v, b.v);
  }
  EXPECT_EQ(g.rate(), 1.0);
}

TEST(SpeedGovernor, SlippingSlowsTheTargetAlongItsPath) {
  SpeedGovernorParams p;
  p.enabled = true;
  LineReference line(1.0, 3.0);
  GovernedReference g(line, p);
  g.reset();
  const double dt = 0.01;
  Reference r;
  for (int k = 0; k <= 200; ++k) {  // 2 s of slip: the rate falls to min_rate after (1 - min) / slow_down s
    r = g.next(dt * k);
    g.report(true, dt);
  }
  EXPECT_DOUBLE_EQ(g.rate(), p.min_rate);
  EXPECT_NEAR(r.v, p.min_rate * 1.0, 1e-12);
  EXPECT_EQ(r.pose.y, 3.0);                        // the same path
  EXPECT_NEAR(r.pose.x, g.governedTime(), 1e-12);  // x = t on the line, at the governed time
  EXPECT_LT(g.governedTime(), 2.0);
  for (int k = 201; k <= 1200; ++k) {  // grip again: back to full speed at speed_up
    r = g.next(dt * k);
    g.report(false, dt);
  }
  EXPECT_DOUBLE_EQ(g.rate(), 1.0);
  EXPECT_NEAR(r.v, 1.0, 1e-12);
  // reset() starts the target from the beginning at full rate.
  g.reset();
  EXPECT_EQ(g.next(0.0).pose.x, 0.0);
  EXPECT_EQ(g.rate(), 1.0);
}

// The traction control's grip verdict (a torque held back without a slip beyond the target) slows the
// target only with on_grip_limit.
TEST(SpeedGovernor, TheGripVerdictSlowsOnlyWithOnGripLimit) {
  for (bool on_limit : {false, true}) {
    SpeedGovernorParams p;
    p.enabled = true;
    p.on_grip_limit = on_limit;
    LineReference line(1.0, 3.0);
    GovernedReference g(line, p);
    g.reset();
    for (int k = 0; k <= 100; ++k) {
      g.next(0.01 * k);
      g.report(false, true, 0.01);
    }
    if (on_limit)
      EXPECT_LT(g.rate(), 1.0);
    else
      EXPECT_EQ(g.rate(), 1.0);
  }
}

TEST(SpeedGovernor, BadParametersAreRefused) {
  SpeedGovernorParams p;
  p.min_rate = 0.0;
  EXPECT_NE(p.validate().find("speed_governor/min_rate"), std::string::npos);
  LineReference line;
  EXPECT_THROW(GovernedReference(line, p), std::invalid_argument);
}
