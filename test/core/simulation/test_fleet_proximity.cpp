// The fleet's proximity check: pairs compared at equal stamps whatever order the robots' states come in,
// the closest approach, encounters below the safety distance with their span, and bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "sowing_robot/core/simulation/fleet_proximity.h"

namespace sowing_robot {
namespace core {
namespace {

TEST(FleetProximity, ComparesByStampWhateverRobotRunsAhead) {
  FleetProximity p(2, 0.5);
  // Robot 0 runs 10 stamps ahead; robot 1 closes in from 1 m to 0.2 m (k = 8) and goes back to 0.3 m.
  for (int k = 0; k < 10; ++k) EXPECT_TRUE(p.add(0, k * 1000000, 0.0, 0.0).empty());
  EXPECT_EQ(p.compared(), 0);
  EXPECT_EQ(p.pending(), 10u);
  int begun = 0;
  for (int k = 0; k < 10; ++k)
    begun += static_cast<int>(p.add(1, k * 1000000, 0.0, 1.0 - 0.1 * (k < 8 ? k : 16 - k)).size());
  EXPECT_EQ(p.compared(), 10);
  EXPECT_EQ(begun, 1);
  ASSERT_EQ(p.encounters().size(), 1u);
  const auto& e = p.encounters()[0];
  EXPECT_EQ(e.a, 0);
  EXPECT_EQ(e.b, 1);
  EXPECT_NEAR(e.begin, 0.006, 1e-12);       // 1 - 0.6 = 0.4 < 0.5 first at k = 6
  EXPECT_NEAR(e.min_distance, 0.2, 1e-12);  // at k = 8
  EXPECT_TRUE(e.open);
  EXPECT_NEAR(p.closest(), 0.2, 1e-12);
  EXPECT_NEAR(p.closestTime(), 0.008, 1e-12);
}

TEST(FleetProximity, EncounterClosesWhenThePairSeparatesAndThreeRobotsArePaired) {
  FleetProximity p(3, 1.0);
  const double y1[] = {2.0, 0.5, 0.5, 2.0};
  for (int k = 0; k < 4; ++k) {
    p.add(2, k, 10.0, 0.0);
    p.add(1, k, 0.0, y1[k]);
    p.add(0, k, 0.0, 0.0);
  }
  ASSERT_EQ(p.encounters().size(), 1u);
  EXPECT_FALSE(p.encounters()[0].open);
  EXPECT_NEAR(p.encounters()[0].end - p.encounters()[0].begin, 1e-9, 1e-15);
  EXPECT_EQ(p.closestA(), 0);
  EXPECT_EQ(p.closestB(), 1);
}

TEST(FleetProximity, SkippedStampsRepeatsAndBadInputAreHarmless) {
  FleetProximity p(2, 1.0);
  p.add(0, 0, 0, 0);
  p.add(0, 2, 0, 0);
  p.add(1, 1, 5, 0);  // robot 0 never sends stamp 1: dropped
  p.add(1, 2, 5, 0);
  EXPECT_EQ(p.compared(), 1);
  EXPECT_TRUE(p.add(1, 2, 0, 0).empty());  // a repeat
  EXPECT_TRUE(p.add(0, 3, NAN, 0).empty());
  EXPECT_TRUE(p.add(7, 3, 0, 0).empty());
  EXPECT_THROW(FleetProximity(1, 1.0), std::invalid_argument);
  EXPECT_THROW(FleetProximity(2, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace sowing_robot
