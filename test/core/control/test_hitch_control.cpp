// Slip-limit hitch control (core/control/hitch_control.h): off it never raises the tool; on, it raises it
// once the traction control's grip verdict has stood raise_after seconds without a break, and lowers it
// only after the robot has travelled lower_after metres without the verdict (not while it stands);
// bad parameters are refused.
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
