// Traction control (core/control/traction_control.h): off and on gripping wheels it passes the torques;
// a slipping wheel's torque is cut at once and recovers at the raise rate; the estimate uses the wheel's
// speed against its contact point's ground speed, or against a reference that follows it no faster than
// max_ground_accel; bad parameters are refused.
#include <gtest/gtest.h>

#include <cmath>

#include "sowing_robot/core/control/traction_control.h"

using namespace sowing_robot::core;

namespace {
TractionControlParams on() {
  TractionControlParams p;
  p.enabled = true;
  return p;
}
constexpr double kL = 0.2, kDt = 0.001;
}  // namespace

TEST(TractionControl, OffOrGrippingItPassesTheTorques) {
  TractionControl off(TractionControlParams{}, kL), tc(on(), kL);
  const WheelGroundSpeeds grip{1.0 + kL * 0.5, 1.0 - kL * 0.5, 1.0, 0.5};  // the wheels roll: no slip
  for (int i = 0; i < 100; ++i) {
    const WheelTorques a = off.limit({50.0, -7.0}, {5.0, 0.0, 0.0, 0.0}, kDt);
    EXPECT_EQ(a.right, 50.0);
    EXPECT_EQ(a.left, -7.0);
    const WheelTorques b = tc.limit({3.0, -2.0}, grip, kDt);
    EXPECT_EQ(b.right, 3.0);
    EXPECT_EQ(b.left, -2.0);
  }
  EXPECT_FALSE(tc.slipping());
  EXPECT_NEAR(tc.slip(0), 0.0, 1e-12);
}

TEST(TractionControl, ASlippingWheelIsCutAndRecovers) {
  const TractionControlParams p = on();
  TractionControl tc(p, kL);
  // The right wheel turns at 2 m/s over ground at 1 m/s (slip 0.5); the left rolls.
  const WheelGroundSpeeds spin{2.0, 1.0, 1.0, 0.0};
  WheelTorques out = tc.limit({5.0, 5.0}, spin, kDt);
  EXPECT_TRUE(tc.slipping());
  EXPECT_NEAR(tc.slip(0), 0.5, 1e-12);
  EXPECT_EQ(out.left, 5.0);
  EXPECT_LT(out.right, 5.0);  // cut from the first period on (from the torque sent, not from max_torque)
  for (int i = 0; i < 200; ++i) out = tc.limit({5.0, 5.0}, spin, kDt);
  EXPECT_NEAR(out.right, std::max(p.min_torque, 5.0 * std::exp(-p.cut_rate * 0.201)), 1e-9);
  // Gripping again: the ceiling rises linearly at raise_rate.
  const double from = tc.ceiling(0);
  const WheelGroundSpeeds grip{1.0, 1.0, 1.0, 0.0};
  for (int i = 0; i < 500; ++i) out = tc.limit({5.0, 5.0}, grip, kDt);
  EXPECT_NEAR(tc.ceiling(0), from + p.raise_rate * 0.5, 1e-9);
  EXPECT_NEAR(out.right, from + p.raise_rate * 0.5, 1e-9);
  EXPECT_FALSE(tc.slipping());
  // Braking slip (a wheel slower than the ground) is cut the same way.
  out = tc.limit({-5.0, 0.0}, {0.0, 1.0, 1.0, 0.0}, kDt);
  EXPECT_TRUE(tc.slipping());
  EXPECT_TRUE(tc.slippingAsFed());  // without the bound, the same verdict
  EXPECT_GT(out.right, -5.0);
  tc.reset();
  EXPECT_EQ(tc.ceiling(0), p.max_torque);
}

// limiting(): the verdict the hitch control and the governor read -- a command cut to the ceiling, not a slip.
TEST(TractionControl, LimitingSaysWhenACommandIsHeldBack) {
  TractionControl tc(on(), kL);
  const WheelGroundSpeeds spin{2.0, 1.0, 1.0, 0.0}, grip{1.0, 1.0, 1.0, 0.0};
  tc.limit({5.0, 5.0}, grip, kDt);
  EXPECT_FALSE(tc.limiting());
  tc.limit({5.0, 5.0}, spin, kDt);  // cut at once: held back
  EXPECT_TRUE(tc.limiting());
  EXPECT_TRUE(tc.slipping());
  // Gripping again, the ceiling (about 4.9 N·m) still holds a 5 N·m command back, not a 1 N·m one.
  tc.limit({5.0, 5.0}, grip, kDt);
  EXPECT_FALSE(tc.slipping());
  EXPECT_TRUE(tc.limiting());
  tc.limit({1.0, -1.0}, grip, kDt);
  EXPECT_FALSE(tc.limiting());
  TractionControl off(TractionControlParams{}, kL);
  off.limit({500.0, 5.0}, spin, kDt);
  EXPECT_FALSE(off.limiting());
}

// Both wheels spinning up together under a fed twist that follows them (the encoders): slip 0 as fed. With
// max_ground_accel the reference ground speed rises no faster than that, so the spin shows and is cut; a fed
// speed that changes within the bound is taken as it is.
TEST(TractionControl, ABoundOnGroundAccelerationShowsWheelsSpinningUpTogether) {
  TractionControlParams p = on();
  TractionControl blind(p, kL);
  p.max_ground_accel = 1.0;
  TractionControl bounded(p, kL);
  double speed = 0.5;  // the wheels and the fed speed: 0.5 m/s, spinning up at 20 m/s^2
  WheelTorques a{}, b{};
  for (int i = 0; i < 50; ++i, speed += 20.0 * kDt) {
    const WheelGroundSpeeds fed{speed, speed, speed, 0.0};
    a = blind.limit({5.0, 5.0}, fed, kDt);
    b = bounded.limit({5.0, 5.0}, fed, kDt);
  }
  EXPECT_EQ(a.right, 5.0);
  EXPECT_FALSE(blind.slipping());
  EXPECT_FALSE(blind.slippingAsFed());
  // After 50 ms the wheels turn at 1.5 m/s over a reference of 0.5 + 1.0 x 0.049 m/s: slip 0.63, both cut.
  EXPECT_NEAR(bounded.slip(0), (1.48 - 0.549) / 1.48, 1e-9);
  EXPECT_NEAR(bounded.slip(1), bounded.slip(0), 1e-12);
  EXPECT_TRUE(bounded.slipping());
  // The no-traction check's input stays the slip against the fed speed: none here (the wheels are the fed speed).
  EXPECT_FALSE(bounded.slippingAsFed());
  EXPECT_LT(b.right, 5.0);
  EXPECT_LT(b.left, 5.0);
  // A robot speeding up at 0.5 m/s^2 (within the bound), turning at 0.5 rad/s: no slip, nothing cut.
  TractionControl smooth(p, kL);
  speed = 0.5;
  for (int i = 0; i < 1000; ++i, speed += 0.5 * kDt) {
    const WheelTorques c = smooth.limit({5.0, 5.0}, {speed + kL * 0.5, speed - kL * 0.5, speed, 0.5}, kDt);
    EXPECT_EQ(c.right, 5.0);
    EXPECT_FALSE(smooth.slipping());
  }
  EXPECT_NEAR(smooth.slip(0), 0.0, 1e-12);
  // reset() forgets the reference: the next fed speed is taken as it is.
  bounded.reset();
  bounded.limit({5.0, 5.0}, {3.0, 3.0, 3.0, 0.0}, kDt);
  EXPECT_FALSE(bounded.slipping());
}

TEST(TractionControl, BadParametersAreRefused) {
  TractionControlParams p = on();
  p.slip_target = 0.0;
  EXPECT_NE(p.validate().find("traction_control/slip_target"), std::string::npos);
  p = on();
  p.min_torque = 200.0;
  EXPECT_NE(p.validate().find("traction_control/min_torque"), std::string::npos);
  EXPECT_THROW(TractionControl(p, kL), std::invalid_argument);
  EXPECT_THROW(TractionControl(on(), 0.0), std::invalid_argument);
  p = on();
  p.max_ground_accel = -1.0;
  EXPECT_NE(p.validate().find("traction_control/max_ground_accel"), std::string::npos);
}
