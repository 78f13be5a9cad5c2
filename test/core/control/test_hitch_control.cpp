// Slip-limit hitch control (core/control/hitch_control.h): off it never raises the tool; on, it raises it
// once the traction control's grip verdict has stood raise_after seconds without a break, and lowers it
// only after the robot has travelled lower_after metres without the verdict (not while it stands);
// bad parameters are refused. With depth control the drill runs shallower before it is raised.
#include <gtest/gtest.h>

#include "sowing_robot/core/control/hitch_control.h"

using namespace sowing_robot::core;

namespace {
constexpr double kDt = 0.001;
HitchControlParams on(double raise_after, double lower_after) {
  HitchControlParams p;
  p.enabled = true;
  p.raise_after = raise_after;
  p.lower_after = lower_after;
  return p;
}
}  // namespace

TEST(HitchControl, OffItNeverRaises) {
  HitchControl off(HitchControlParams{});
  for (int k = 0; k < 5000; ++k) EXPECT_FALSE(off.update(true, 0.001, kDt));
  EXPECT_EQ(off.raises(), 0);
}

TEST(HitchControl, RaisesOnceTheVerdictHasStoodRaiseAfter) {
  HitchControl h(on(0.0495, 1.0));  // the 50th period of 1 ms
  for (int k = 0; k < 49; ++k) EXPECT_FALSE(h.update(true, 0.001, kDt)) << k;
  EXPECT_FALSE(h.update(false, 0.001, kDt));  // a break starts it again
  for (int k = 0; k < 49; ++k) EXPECT_FALSE(h.update(true, 0.001, kDt));
  EXPECT_TRUE(h.update(true, 0.001, kDt));  // the 50th period in a row
  EXPECT_EQ(h.raises(), 1);
  // raise_after 0: at the first period of the verdict.
  HitchControl at_once(on(0.0, 1.0));
  EXPECT_TRUE(at_once.update(true, 0.0, kDt));
}

TEST(HitchControl, LowersAfterLowerAfterMetresOfGrip) {
  HitchControl h(on(0.0, 1.0));
  ASSERT_TRUE(h.update(true, 0.001, kDt));
  // Standing still with grip: it stays up (the travel, not the time, lowers it).
  for (int k = 0; k < 10000; ++k) EXPECT_TRUE(h.update(false, 0.0, kDt));
  // 0.999 m of travel at 1 m/s: still up; the verdict on the way starts the count again.
  for (int k = 0; k < 999; ++k) EXPECT_TRUE(h.update(false, 0.001, kDt));
  EXPECT_TRUE(h.update(true, 0.001, kDt));
  for (int k = 0; k < 999; ++k) EXPECT_TRUE(h.update(false, 0.001, kDt));
  EXPECT_FALSE(h.update(false, 0.0011, kDt));  // past 1 m since the verdict last stood
  EXPECT_EQ(h.raises(), 1);
  EXPECT_TRUE(h.update(true, 0.001, kDt));  // and raised again on the next verdict
  EXPECT_EQ(h.raises(), 2);
  h.reset();
  EXPECT_FALSE(h.raised());
  EXPECT_EQ(h.raises(), 0);
}

TEST(HitchControl, BadParametersAreRefused) {
  HitchControlParams p = on(-0.1, 1.0);
  EXPECT_NE(p.validate().find("hitch_control/raise_after"), std::string::npos);
  EXPECT_THROW(HitchControl{p}, std::invalid_argument);
  p = on(0.0, -1.0);
  EXPECT_NE(p.validate().find("hitch_control/lower_after"), std::string::npos);
  EXPECT_EQ(on(0.0, 5.0).validate(), "");
}

// Depth control: on the verdict the drill first runs shallower at depth_rate (not raised), is raised only
// once it is at depth_shallowest and the verdict still stands (raise_after), comes down there after lower_after
// metres of grip and goes back to its working depth after deepen_after metres, at depth_rate.
TEST(HitchControl, DepthControlRunsShallowerFirstLiftsLastAndGoesBackDown) {
  HitchControlParams p = on(0.0095, 1.0);  // the 10th period of 1 ms at the shallowest
  p.depth_control = true;
  p.depth_nominal = 0.04;
  p.depth_shallowest = 0.03;
  p.depth_rate = 0.02;  // 1 cm in 0.5 s
  p.deepen_after = 0.5;
  HitchControl h(p);
  EXPECT_TRUE(h.controlsDepth());
  EXPECT_EQ(h.depth(), 0.04);
  // 0.25 s of the verdict: half way, still down.
  for (int k = 0; k < 250; ++k) EXPECT_FALSE(h.update(true, 0.001, kDt)) << k;
  EXPECT_NEAR(h.depth(), 0.035, 1e-12);
  // A break with little travel (below deepen_after) keeps the depth; the verdict goes on shallower.
  for (int k = 0; k < 100; ++k) EXPECT_FALSE(h.update(false, 0.001, kDt));
  EXPECT_NEAR(h.depth(), 0.035, 1e-12);
  int periods = 0;
  while (h.depth() > 0.03 && periods < 1000) {
    EXPECT_FALSE(h.update(true, 0.001, kDt));
    ++periods;
  }
  EXPECT_NEAR(periods, 250, 1);
  EXPECT_EQ(h.depth(), 0.03);  // at the shallowest, not yet raised
  EXPECT_EQ(h.raises(), 0);
  // At the shallowest the verdict must stand raise_after (10 periods) before the lift.
  for (int k = 0; k < 9; ++k) EXPECT_FALSE(h.update(true, 0.001, kDt)) << k;
  EXPECT_TRUE(h.update(true, 0.001, kDt));
  EXPECT_EQ(h.raises(), 1);
  EXPECT_EQ(h.depth(), 0.03);  // raised, it stays set to the depth it comes down at
  // 1 m of grip: lowered, at the shallowest (deepen_after passed on the way: it deepens from then on).
  for (int k = 0; k < 999; ++k) EXPECT_TRUE(h.update(false, 0.001, kDt));
  EXPECT_FALSE(h.update(false, 0.0011, kDt));
  EXPECT_NEAR(h.depth(), 0.03 + 0.02 * kDt, 1e-12);
  // Back to the working depth in 0.5 s more of grip, and no deeper.
  for (int k = 0; k < 600; ++k) EXPECT_FALSE(h.update(false, 0.001, kDt));
  EXPECT_EQ(h.depth(), 0.04);
  // A standing robot does not deepen (travel, not time), nor does it lift at once on a new verdict.
  EXPECT_FALSE(h.update(true, 0.0, kDt));
  const double after = h.depth();
  EXPECT_LT(after, 0.04);
  for (int k = 0; k < 1000; ++k) h.update(false, 0.0, kDt);
  EXPECT_EQ(h.depth(), after);
  h.reset();
  EXPECT_EQ(h.depth(), 0.04);
  EXPECT_FALSE(h.raised());
}

// Without depth control the depth stays nominal and the hitch raises at once, as before.
TEST(HitchControl, WithoutDepthControlTheDepthStaysNominal) {
  HitchControl h(on(0.0, 1.0));
  EXPECT_FALSE(h.controlsDepth());
  EXPECT_TRUE(h.update(true, 0.001, kDt));
  EXPECT_EQ(h.depth(), HitchControlParams{}.depth_nominal);
  HitchControlParams p = on(0.0, 1.0);
  p.depth_control = true;
  p.depth_shallowest = 0.05;  // deeper than the working depth
  EXPECT_NE(p.validate().find("hitch_control/depth_shallowest"), std::string::npos) << p.validate();
  EXPECT_THROW(HitchControl{p}, std::invalid_argument);
}
