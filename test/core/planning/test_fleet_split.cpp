// A fleet sharing one field (fleet_split.h) on the L-shaped field of config/fields/l_field_local.yaml with 3 robots:
// the split, the planned waits that keep the robots apart, and the figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>
#include <stdexcept>
#include <vector>

#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/field_path_follower.h"
#include "sowing_robot/core/planning/fleet_split.h"

using namespace sowing_robot::core;

namespace {

/// config/fields/l_field_local.yaml (the local frame of l_field.geojson); the core's tests do not read files.
FieldBoundary lField() {
  FieldBoundary f;
  f.outer = {{0, 0}, {121.3, 1.2}, {120.4, 55.8}, {61.0, 56.5}, {59.8, 110.2}, {-0.6, 109.4}};
  f.voids = {{{20, 24}, {31, 21}, {39, 27}, {37, 37}, {27, 40}, {19, 34}}};
  f.circles = {Obstacle{95.0, 30.0, 1.2}};
  return f;
}

/// The table's defaults: config/field.yaml's drill and turns (one row per pass, 1 m apart, two headland passes,
/// min_turn_radius 0.5 m, rate 10 1/m^2), heading auto.
CoverageParams drill() { return CoverageParams(); }

/// Three robots side by side south of the field, 5 m apart, facing north.
std::vector<Pose2D> starts(int n) {
  std::vector<Pose2D> s;
  for (int i = 0; i < n; ++i) s.push_back({5.0 + 5.0 * i, -5.0, M_PI / 2});
  return s;
}

class FleetSplit : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    plan_ = std::make_unique<CoveragePlan>(planCoverage(lField(), drill()));
    follower_ = fieldFollowerParams(FieldParams());
    fleet_ = std::make_unique<FleetPlan>(splitCoverage(*plan_, 3, starts(3), drill(), follower_));
    kept_ = std::make_unique<FleetPlan>(*fleet_);
    keepApart(*kept_, *plan_, FleetParams());
    single_ = std::make_unique<FleetPlan>(splitCoverage(*plan_, 1, starts(1), drill(), follower_));
  }
  static std::unique_ptr<CoveragePlan> plan_;
  static PathParams follower_;
  static std::unique_ptr<FleetPlan> fleet_, kept_, single_;
};
std::unique_ptr<CoveragePlan> FleetSplit::plan_;
PathParams FleetSplit::follower_;
std::unique_ptr<FleetPlan> FleetSplit::fleet_, FleetSplit::kept_, FleetSplit::single_;

}  // namespace

TEST_F(FleetSplit, EverySwathAndLoopGoesToOneRobotInContiguousBlocks) {
  const FleetPlan& f = *fleet_;
  ASSERT_EQ(f.shares.size(), 3u);
  int next = 0;
  std::set<int> robots, loops;
  for (std::size_t i = 0; i < f.shares.size(); ++i) {
    const RobotShare& s = f.shares[i];
    EXPECT_EQ(s.rank, static_cast<int>(i));
    EXPECT_EQ(s.first_swath, next) << "blocks follow each other in route order";
    EXPECT_GT(s.swaths, 0);
    next += s.swaths;
    robots.insert(s.robot);
    for (const int j : s.loops) EXPECT_TRUE(loops.insert(j).second) << "loop " << j << " given twice";
    // Its path starts at its start pose and runs through its first and last swath.
    ASSERT_FALSE(s.path.points.empty());
    EXPECT_LT((s.path.points.front() - Eigen::Vector2d(s.start.x, s.start.y)).norm(), 1e-9);
    EXPECT_EQ(s.path.tool_down.size() + 1, s.path.points.size());
    EXPECT_FALSE(s.path.tool_down.front()) << "the approach is tool up";
  }
  EXPECT_EQ(next, static_cast<int>(plan_->swaths.size()));
  EXPECT_EQ(robots.size(), 3u);
  EXPECT_EQ(loops.size(), plan_->headland_rings.size());
  // The shares sow what the single route sows.
  double sown = 0.0;
  for (const RobotShare& s : f.shares) sown += toolArea(s.path, 1.0);
  EXPECT_NEAR(sown, toolArea(plan_->route, 1.0), 1e-6 * sown);
  EXPECT_NEAR(toolArea(single_->shares[0].path, 1.0), toolArea(plan_->route, 1.0), 1e-6 * sown);
}

TEST_F(FleetSplit, TheSharesAreBalancedByDrivingTime) {
  double lo = 1e18, hi = 0.0;
  for (const RobotShare& s : fleet_->shares) {
    lo = std::min(lo, s.timed.duration());
    hi = std::max(hi, s.timed.duration());
    // The estimate the split balanced is the follower's time within a few percent.
    EXPECT_NEAR(s.estimate, s.timed.duration(), 0.05 * s.timed.duration());
  }
  EXPECT_LT(hi / lo, 1.05) << "longest " << hi << " s, shortest " << lo << " s";
  EXPECT_LT(hi, 0.36 * single_->shares[0].timed.duration());
}

TEST_F(FleetSplit, ThePlannedWaitsKeepTheRobotsApart) {
  const FleetPlan& k = *kept_;
  EXPECT_TRUE(k.conflict_free);
  const FleetCheck again = checkFleet(k, *plan_, FleetParams());
  EXPECT_TRUE(again.conflicts.empty());
  EXPECT_GE(again.min_separation, FleetParams().safety_distance);
  // An independent look: every robot's timed path every second, waits included.
  for (double t = 0.0; t < k.makespan(); t += 1.0)
    for (std::size_t a = 0; a < k.shares.size(); ++a)
      for (std::size_t b = a + 1; b < k.shares.size(); ++b) {
        const RobotShare &ra = k.shares[a], &rb = k.shares[b];
        if (t > ra.end() || t > rb.end() || t < ra.wait || t < rb.wait) continue;
        const Pose2D pa = ra.poseAt(t), pb = rb.poseAt(t);
        ASSERT_GE(std::hypot(pa.x - pb.x, pa.y - pb.y), FleetParams().safety_distance - 0.3)
            << "robots " << a << ", " << b << " at " << t << " s";
      }
  // Without the waits the split alone is not conflict-free or the waits are zero: either way consistent.
  const FleetCheck before = checkFleet(*fleet_, *plan_, FleetParams());
  EXPECT_EQ(before.conflicts.empty(), k.waits_added == 0);
  // The waits reported add up to the shares' waits, each for a conflict of its robot, the later one first.
  ASSERT_EQ(static_cast<int>(k.waits.size()), k.waits_added);
  std::vector<double> sum(k.shares.size(), 0.0);
  for (const FleetWait& w : k.waits) {
    EXPECT_GT(w.added, 0.0);
    EXPECT_TRUE(w.share == w.conflict.a || w.share == w.conflict.b);
    sum[w.share] += w.added;
  }
  for (std::size_t i = 0; i < k.shares.size(); ++i) EXPECT_NEAR(sum[i], k.shares[i].wait, 1e-9);
}

TEST_F(FleetSplit, TheFleetSowsAtLeast2point7TimesTheRateOfOneRobot) {
  const DriveEnergyParams e;
  const FleetFigures one = fleetFigures(*single_, 1.0, e), three = fleetFigures(*kept_, 1.0, e);
  EXPECT_NEAR(three.area, one.area, 1e-6 * one.area);
  EXPECT_GT(three.area_rate / one.area_rate, 2.7) << three.area_rate << " vs " << one.area_rate << " ha/h";
  // The same work in the fleet costs about the same energy per hectare (three approaches, joins).
  EXPECT_GT(one.energy_per_ha, 0.0);
  EXPECT_NEAR(three.energy_per_ha / one.energy_per_ha, 1.0, 0.05);
}

TEST(CoverageJoin, JoinsTwoPosesToolUpWithinTheTurnBounds) {
  const CoverageParams p = drill();
  for (const Pose2D& to :
       {Pose2D{20.0, 5.0, 0.0}, Pose2D{-3.0, 8.0, M_PI}, Pose2D{0.0, 1.0, M_PI}, Pose2D{4.0, -6.0, 2.0}}) {
    const Pose2D from{0.0, 0.0, 0.0};
    const CoveragePath j = coverageJoin(from, to, p);
    ASSERT_GE(j.points.size(), 2u);
    EXPECT_LT(j.points.front().norm(), 1e-12);
    EXPECT_LT((j.points.back() - Eigen::Vector2d(to.x, to.y)).norm(), 1e-9);
    EXPECT_EQ(j.tool_down.size() + 1, j.points.size());
    for (const bool t : j.tool_down) EXPECT_FALSE(t);
    // Leaves along from's heading and arrives along to's; the circle through three points keeps min_turn_radius.
    const Eigen::Vector2d d0 = j.points[1] - j.points[0], d1 = j.points.back() - j.points[j.points.size() - 2];
    EXPECT_LT(std::fabs(std::atan2(d0.y(), d0.x()) - from.theta), 0.2);
    EXPECT_LT(std::fabs(std::remainder(std::atan2(d1.y(), d1.x()) - to.theta, 2.0 * M_PI)), 0.2);
    for (std::size_t i = 1; i + 1 < j.points.size(); ++i) {
      const Eigen::Vector2d a = j.points[i] - j.points[i - 1], b = j.points[i + 1] - j.points[i],
                            c = j.points[i + 1] - j.points[i - 1];
      const double kappa = 2.0 * std::fabs(a.x() * b.y() - a.y() * b.x()) / (a.norm() * b.norm() * c.norm());
      EXPECT_LT(kappa, 1.07 / p.min_turn_radius) << "point " << i;
    }
  }
  EXPECT_EQ(coverageJoin({1.0, 2.0, 0.5}, {1.0, 2.0, 0.5}, p).points.size(), 1u);
  EXPECT_THROW(coverageJoin({NAN, 0.0, 0.0}, {1.0, 0.0, 0.0}, p), std::invalid_argument);
}

TEST(FleetEnergy, AStraightAtConstantSpeedDrawsTheRollingResistancesPowerAndTheCopperLoss) {
  PathParams pp;
  pp.v_max = 1.0;
  pp.a_max = 0.5;
  const PathPlan line({{0.0, 0.0}, {200.0, 0.0}}, PathStart{{0.0, 0.0, 0.0}, 0.0}, pp);
  DriveEnergyParams e;
  const double roll = 0.5 * e.rolling_resistance * e.robot.m() * e.gravity;  // per wheel [N]
  const double tau = e.robot.R * roll, w = 1.0 / e.robot.R;
  const double cruise = 2.0 * (tau * w + tau * tau * e.motor.no_load_speed / e.motor.stall_torque);  // [W]
  const double energy = driveEnergy(line, e, 0.01);
  // The ramps (4 m each way) add the kinetic energy and take the rolling power at lower speed: a few percent.
  EXPECT_GT(energy, cruise * (200.0 - 8.0));
  EXPECT_LT(energy, cruise * line.duration() + 0.5 * e.robot.m0() * 1.0 * 2.0);
  EXPECT_EQ(driveEnergy(PathPlan(), e), 0.0);
}

TEST_F(FleetSplit, RefusesBadArguments) {
  EXPECT_THROW(splitCoverage(*plan_, 0, {}, drill(), follower_), std::invalid_argument);
  EXPECT_THROW(splitCoverage(*plan_, 2, starts(3), drill(), follower_), std::invalid_argument);
  EXPECT_THROW(splitCoverage(*plan_, 9, starts(9), drill(), follower_), std::invalid_argument);
  std::vector<Pose2D> bad = starts(2);
  bad[1].x = NAN;
  EXPECT_THROW(splitCoverage(*plan_, 2, bad, drill(), follower_), std::invalid_argument);
  EXPECT_THROW(splitCoverage(CoveragePlan(), 1, starts(1), drill(), follower_), std::invalid_argument);
  FleetParams fp;
  fp.safety_distance = 0.0;
  FleetPlan copy = *fleet_;
  EXPECT_THROW(keepApart(copy, *plan_, fp), std::invalid_argument);
  EXPECT_THROW(checkFleet(copy, *plan_, fp), std::invalid_argument);
}
