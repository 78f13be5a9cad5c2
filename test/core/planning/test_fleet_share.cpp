// One robot of a fleet sharing a field as the nodes drive it (fleet_share.h): the start poses, the same split
// whichever robot plans it, and the share's reference with its planned wait and the run-time hold.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "sowing_robot/core/planning/coverage_follower.h"
#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/fleet_share.h"

using namespace sowing_robot::core;

namespace {

/// A 4 m x 8 m field without headland: four 1 m swaths.
FieldBoundary smallField() {
  FieldBoundary f;
  f.outer = {{0, 0}, {4, 0}, {4, 8}, {0, 8}};
  return f;
}

CoverageParams smallDrill() {
  CoverageParams p;
  p.headland_passes = 0;
  return p;
}

FleetShareParams twoRobots(int index) {
  FleetShareParams f;
  f.robots = 2;
  f.index = index;
  f.start_x = 0.5;
  f.start_spacing = 2.0;
  f.start_back = 2.0;
  f.keep_apart = false;
  return f;
}

}  // namespace

TEST(FleetShare, StartsSideBySideSouthOfTheField) {
  FleetShareParams p;
  p.robots = 3;
  const auto s = fleetStarts({{10, 20}, {50, 18}, {40, 60}}, p);
  ASSERT_EQ(s.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(s[i].x, 10 + 5.0 + 5.0 * i);
    EXPECT_DOUBLE_EQ(s[i].y, 18 - 5.0);
    EXPECT_DOUBLE_EQ(s[i].theta, M_PI / 2);
  }
  FleetShareParams bad = p;
  bad.index = 3;
  EXPECT_FALSE(bad.validate().empty());
  bad = p;
  bad.robots = 0;
  bad.yield = true;
  EXPECT_FALSE(bad.validate().empty());
}

TEST(FleetShare, EveryRobotPlansTheSameSplitAndDrivesItsOwnShare) {
  const CoveragePlan plan = planCoverage(smallField(), smallDrill());
  const PathParams follower = coverageFollowerParams(FieldParams(), smallDrill());
  const FleetShare a = planFleetShare(plan, twoRobots(0), smallDrill(), follower);
  const FleetShare b = planFleetShare(plan, twoRobots(1), smallDrill(), follower);
  ASSERT_EQ(a.fleet.shares.size(), 2u);
  EXPECT_EQ(a.own().robot, 0);
  EXPECT_EQ(b.own().robot, 1);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(a.fleet.shares[i].first_swath, b.fleet.shares[i].first_swath);
    EXPECT_EQ(a.fleet.shares[i].path.points, b.fleet.shares[i].path.points);
    EXPECT_EQ(a.fleet.shares[i].wait, b.fleet.shares[i].wait);
  }
  EXPECT_EQ(a.own().path.points.front().x(), a.own().start.x);
  // The one robot's route begins on the route, heading along it.
  const Pose2D r = routeStart(plan);
  EXPECT_DOUBLE_EQ(r.x, plan.route.points.front().x());
  EXPECT_DOUBLE_EQ(r.y, plan.route.points.front().y());
}

TEST(FleetShare, TheReferenceWaitsThenFollowsItsPath) {
  PathParams pp;
  const Pose2D start{0, 0, 0};
  const std::vector<Eigen::Vector2d> pts{{0, 0}, {10, 0}};
  PathReference alone(pp, start, pts);
  FleetShareReference ref(std::make_unique<PathReference>(pp, start, pts), 2.0, 1.0);
  const double dt = 0.001;
  for (int k = 0; k < 2000; ++k) {
    const Reference r = ref.next(k * dt);
    EXPECT_TRUE(r.stop);
    EXPECT_EQ(r.v, 0.0);
    EXPECT_FALSE(ref.started());
  }
  for (int k = 2000; k < 40000; ++k) {  // never held: the path shifted by the wait
    const Reference r = ref.next(k * dt);
    const Reference a = alone.next(k * dt - 2.0);
    ASSERT_NEAR(r.pose.x, a.pose.x, 1e-12) << k;
    ASSERT_NEAR(r.v, a.v, 1e-12) << k;
    ASSERT_EQ(r.stop, a.stop) << k;
  }
  EXPECT_DOUBLE_EQ(ref.progress(), 1.0);
  EXPECT_THROW(FleetShareReference(std::make_unique<PathReference>(pp, start, pts), -1.0, 1.0), std::invalid_argument);
  EXPECT_THROW(FleetShareReference(std::make_unique<PathReference>(pp, start, pts), 0.0, 0.0), std::invalid_argument);
}

TEST(FleetShare, AHoldSlowsToAStopStandsAndGoesOnToTheEnd) {
  PathParams pp;
  const Pose2D start{0, 0, 0};
  FleetShareReference ref(std::make_unique<PathReference>(pp, start, std::vector<Eigen::Vector2d>{{0, 0}, {30, 0}}),
                          0.0, 2.0);
  const double dt = 0.001;
  int k = 0;
  for (; k < 10000; ++k) ref.next(k * dt);  // at speed
  ref.setHold(true);
  double x_stop = 0.0;
  for (int i = 0; i < 5000; ++i, ++k) {
    const Reference r = ref.next(k * dt);
    EXPECT_GE(r.v, 0.0);
    if (i == 2100) {
      EXPECT_TRUE(r.stop);
      EXPECT_EQ(r.v, 0.0);
      EXPECT_TRUE(ref.standing());
      x_stop = r.pose.x;
    }
    if (i > 2100) {
      EXPECT_EQ(r.pose.x, x_stop);
    }
  }
  const double progress = ref.progress();
  EXPECT_GT(progress, 0.1);
  EXPECT_LT(progress, 1.0);
  ref.setHold(false);
  Reference r;
  for (int i = 0; i < 60000; ++i, ++k) r = ref.next(k * dt);
  EXPECT_DOUBLE_EQ(ref.progress(), 1.0);
  EXPECT_NEAR(r.pose.x, 30.0, 1e-6);
  EXPECT_FALSE(ref.standing());
}

TEST(FleetShare, SplitsARouteWithTheToolsRunOut) {
  // coverage/run_out > 0 (the nodes read it from the URDF): each swath is entered tool up for run_out and left run_out
  // past its end; the split finds the swaths on such a route and hands the whole stretch on.
  CoverageParams cp = smallDrill();
  cp.run_out = 0.4;
  const CoveragePlan plan = planCoverage(smallField(), cp);
  const FleetShare a = planFleetShare(plan, twoRobots(0), cp, coverageFollowerParams(FieldParams(), cp));
  double down = 0.0;
  for (const RobotShare& s : a.fleet.shares)
    for (std::size_t k = 0; k + 1 < s.path.points.size(); ++k)
      if (s.path.tool_down[k]) down += (s.path.points[k + 1] - s.path.points[k]).norm();
  double planned = 0.0;
  for (std::size_t k = 0; k + 1 < plan.route.points.size(); ++k)
    if (plan.route.tool_down[k]) planned += (plan.route.points[k + 1] - plan.route.points[k]).norm();
  EXPECT_NEAR(down, planned, 1e-9);
}
