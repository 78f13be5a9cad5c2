// Footprint geometry (hull, radii, signed distance to a disc) and the contact monitor.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sowing_robot/core/model/contact.h"
#include "sowing_robot/core/model/footprint.h"

using sowing_robot::core::ContactMonitor;
using sowing_robot::core::Footprint;
using sowing_robot::core::Pose2D;

namespace {
/// A 0.6 x 0.4 m rectangle from x = -0.2 to 0.4, y = -0.2 to 0.2, with interior and duplicate points.
Footprint rectangle() {
  return Footprint::convexHull(
      {{-0.2, -0.2}, {0.4, -0.2}, {0.4, 0.2}, {-0.2, 0.2}, {0.1, 0.0}, {0.4, 0.2}, {0.4, 0.0}});
}
}  // namespace

TEST(Footprint, HullDropsInteriorAndCollinearPointsAndIsCounterClockwise) {
  const Footprint f = rectangle();
  ASSERT_EQ(f.vertices().size(), 4u);
  EXPECT_EQ(f.validate(), "");
  EXPECT_NEAR(f.circumscribedRadius(), std::hypot(0.4, 0.2), 1e-15);
  EXPECT_NEAR(f.inscribedRadius(), 0.2, 1e-15);
  // A hull that does not contain base_link's origin is refused.
  EXPECT_NE(Footprint::convexHull({{1, 1}, {2, 1}, {2, 2}}).validate(), "");
  EXPECT_NE(Footprint::convexHull({{1, 1}, {2, 1}}).validate(), "");
}

TEST(Footprint, SignedDistanceToADisc) {
  const Footprint f = rectangle();
  // Robot at the origin heading +x: disc 1 m ahead of the front edge (x = 0.4).
  EXPECT_NEAR(f.distanceToCircle({0, 0, 0}, {1.7, 0.0}, 0.3), 1.0, 1e-12);
  // Beside: the left edge y = 0.2; a disc at y = 0.45, r = 0.3 overlaps by 0.05.
  EXPECT_NEAR(f.distanceToCircle({0, 0, 0}, {0.0, 0.45}, 0.3), -0.05, 1e-12);
  // Off a corner: (0.4, 0.2) to (0.7, 0.6) is 0.5.
  EXPECT_NEAR(f.distanceToCircle({0, 0, 0}, {0.7, 0.6}, 0.1), 0.4, 1e-12);
  // Centre inside the body: depth = distance to the nearest edge + radius.
  EXPECT_NEAR(f.distanceToCircle({0, 0, 0}, {0.3, 0.0}, 0.1), -0.2, 1e-12);
  // Placed: at (5, 3) heading +90 deg the front edge faces +y, so a disc at (5, 3.4 + 0.3 + 0.5) is 0.5 away.
  EXPECT_NEAR(f.distanceToCircle({5, 3, M_PI / 2}, {5.0, 4.2}, 0.3), 0.5, 1e-12);
  // The same disc seen by the robot turned back (heading -90 deg): the rear edge (0.2) faces it.
  EXPECT_NEAR(f.distanceToCircle({5, 3, -M_PI / 2}, {5.0, 4.2}, 0.3), 0.7, 1e-12);
  // Empty footprint: the axle point.
  EXPECT_NEAR(Footprint{}.distanceToCircle({0, 0, 0}, {1.0, 0.0}, 0.3), 0.7, 1e-15);
}

TEST(ContactMonitor, ReportsStartEndObstacleAndDepth) {
  ContactMonitor m(rectangle(), {{3.0, 0.45, 0.3}, {10.0, 5.0, 0.3}});
  // Drive along y = 0 at 1 m/s, 1 ms steps: the left edge (y = 0.2) overlaps obstacle 0 by 0.05 m
  // while the disc's chord at y = 0.2 is under the body.
  bool changed_any = false;
  for (int k = 0; k <= 6000; ++k) changed_any |= m.update(k * 1e-3, {k * 1e-3, 0.0, 0.0});
  m.finish();
  EXPECT_TRUE(changed_any);
  ASSERT_EQ(m.contactCount(), 1u);
  const auto& e = m.events()[0];
  EXPECT_EQ(e.obstacle, 0u);
  EXPECT_FALSE(e.ongoing);
  EXPECT_NEAR(e.max_depth, 0.05, 1e-9);
  // In contact while the disc's x-extent at y = 0.2, 3 +- sqrt(0.3^2 - 0.25^2), meets the body's
  // x range [x - 0.2, x + 0.4].
  const double half = std::sqrt(0.09 - 0.0625);
  EXPECT_NEAR(e.start, 3.0 - half - 0.4, 1.5e-3);
  EXPECT_NEAR(e.end, 3.0 + half + 0.2, 1.5e-3);
  EXPECT_NEAR(m.minClearance(), -0.05, 1e-9);
  EXPECT_EQ(m.minClearanceObstacle(), 0u);
  EXPECT_FALSE(m.inContact());
  EXPECT_NE(m.report().find("contact with obstacle 0"), std::string::npos) << m.report();
}

TEST(ContactMonitor, ClearRunHasNoContactAndTheTrueMinimumClearance) {
  ContactMonitor m(rectangle(), {{3.0, 0.6, 0.3}});
  for (int k = 0; k <= 6000; ++k) m.update(k * 1e-3, {k * 1e-3, 0.0, 0.0});
  EXPECT_EQ(m.contactCount(), 0u);
  EXPECT_NEAR(m.minClearance(), 0.1, 1e-9);  // 0.6 - 0.3 - 0.2
  // A non-finite pose is refused and changes nothing.
  EXPECT_FALSE(m.update(7.0, {std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0}));
  EXPECT_EQ(m.rejected(), 1u);
  EXPECT_NEAR(m.minClearance(), 0.1, 1e-9);
}

TEST(ContactMonitor, RunTimeObstacleListClosesOpenContacts) {
  ContactMonitor m(rectangle(), {{0.0, 0.0, 0.3}});
  EXPECT_TRUE(m.update(0.0, {0, 0, 0}));
  EXPECT_TRUE(m.inContact());
  m.setObstacles({});
  EXPECT_FALSE(m.inContact());
  ASSERT_EQ(m.contactCount(), 1u);
  EXPECT_FALSE(m.events()[0].ongoing);
  EXPECT_THROW(m.setObstacles({{0.0, 0.0, -1.0}}), std::invalid_argument);
}
