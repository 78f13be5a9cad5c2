// The field as a path for the path follower (field/follower path): the producer's points and tool flags, the plan
// the follower makes of them (no turn in place, the field's speed bounds), and closed-loop runs on the 3-row field
// and the thesis field (the body clear of the obstacles, the seeds on the rows, the end at the last row's end), an
// obstacle added at run time, and the benchmark's extra time.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "sowing_robot/core/planning/field_path_follower.h"
#include "sowing_robot/core/simulation/field_run.h"
#include "thesis_field_fixture.h"

namespace sowing_robot {
namespace core {
namespace {

/// config/field.yaml: 3 rows of 30 m, 1 m apart, from (0, 3) along +x, an obstacle on the middle row; the robot
/// starts at (-1, 0, 0) and the path with it (the approach).
FieldRunSetup threeRows() {
  FieldRunSetup s;
  s.field.rows = 3;
  s.field.row_length = 30.0;
  s.field.potential.beta = 4.0;
  s.field.follower = FieldFollower::kPath;
  s.obstacles = {{15.0, 4.0, 0.3}};
  s.scenario.duration = 107.2;  // the path lasts 106.8 s from the row start (every row runs on by run_out)
  s.scenario.duration += approachExtraTime(s);
  return s;
}

FieldParams withStart(const FieldRunSetup& s) {
  FieldParams f = s.field;
  f.start_pose = s.scenario.start;
  return f;
}

TEST(CoveragePath, RowsAreSingleSegmentsWithTheToolDownAndTurnsAreEvenlySampledWithItUp) {
  const FieldRunSetup s = threeRows();
  FieldParams f = s.field;  // no obstacle, no approach: the plain rows and turns
  f.approach = false;
  const FieldPath path(f);
  const CoveragePath c = coveragePath(path, 0.05);
  ASSERT_EQ(c.tool_down.size() + 1, c.points.size());
  // Tool-down segments: exactly the three rows, each one straight segment from row start to row end.
  std::vector<std::size_t> down;
  for (std::size_t k = 0; k < c.tool_down.size(); ++k)
    if (c.tool_down[k]) down.push_back(k);
  ASSERT_EQ(down.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector2d a = c.points[down[i]], b = c.points[down[i] + 1];
    EXPECT_NEAR(a.y(), 3.0 + i, 1e-9);
    EXPECT_NEAR(b.y(), 3.0 + i, 1e-9);
    // The tool's changes are found on the 1 ms sampling: within 1 mm at 1 m/s at either end.
    // Every row runs on until the tool point, which trails the axle by run_out, is at its end.
    EXPECT_NEAR(std::fabs(b.x() - a.x()), 30.0 + f.run_out, 2e-3) << "row " << i;
  }
  // The turns and the lead-ins they leave: points every 5 cm (to the sampling's 1 ms), all within the headland beyond
  // the rows.
  for (std::size_t k = 0; k < c.tool_down.size(); ++k) {
    if (c.tool_down[k]) continue;
    // A lead-in (on a row's line, y = 3, 4 or 5) is straight: one segment of up to run_out.
    const bool on_line = std::fabs(c.points[k].y() - std::round(c.points[k].y())) < 1e-9 &&
                         std::fabs(c.points[k + 1].y() - std::round(c.points[k + 1].y())) < 1e-9;
    EXPECT_LT((c.points[k + 1] - c.points[k]).norm(), (on_line ? f.run_out : 0.0) + 0.05 + 1e-3 + 1e-9);
    EXPECT_TRUE(c.points[k].x() >= 30.0 - 1e-9 || c.points[k].x() <= 1e-9) << c.points[k].transpose();
  }
  EXPECT_THROW(coveragePath(path, 0.0), std::invalid_argument);
}

TEST(FieldPathReference, PlansNoTurnInPlaceKeepsTheFieldsBoundsAndStopsAtTheLastRowsEnd) {
  const FieldRunSetup s = threeRows();
  FieldPathReference ref(withStart(s), s.obstacles);
  const PathPlan& plan = ref.follower().plan();
  EXPECT_EQ(plan.pivots(), 0);
  EXPECT_GT(plan.fillets(), 20);  // the approach, the detour and two turns, in corners every kSpacing
  EXPECT_EQ(ref.status().detours, 1u);
  const double lateral = s.field.turn_speed * s.field.turn_speed / s.field.min_turn_radius;
  double peak_lateral = 0.0, peak_v = 0.0, down_time = 0.0;
  Reference r;
  const double dt = 1e-3;
  for (double t = 0.0; t < ref.duration() + 1.0; t += dt) {
    r = ref.next(t);
    peak_lateral = std::max(peak_lateral, std::fabs(r.v * r.omega));
    peak_v = std::max(peak_v, r.v);
    if (r.tool_down) down_time += dt;
    // Tool down only on the rows (|y - row| within the detour's offset near the obstacle).
    // Each row runs on by run_out past its end (row 1 back to x = -run_out).
    if (r.tool_down) {
      EXPECT_TRUE(r.pose.x > -s.field.run_out - 1e-6 && r.pose.x < 30.0 + s.field.run_out + 1e-6) << t;
    }
  }
  EXPECT_LE(peak_lateral, lateral * (1.0 + 1e-6));
  EXPECT_NEAR(peak_v, s.field.row_speed, 1e-6);
  EXPECT_GT(down_time, 80.0);  // 90 m of rows (less the settle and the detour's slower stretch) at <= 1 m/s
  EXPECT_TRUE(r.stop);
  EXPECT_TRUE(ref.finished(ref.duration()));
  EXPECT_NEAR(r.pose.x, 30.0 + s.field.run_out, 1e-6);  // the tool point at the row end
  EXPECT_NEAR(r.pose.y, 5.0, 1e-6);
  // A clone starts over and repeats the references bit for bit.
  auto copy = ref.clone();
  ref.reset();
  for (double t = 0.0; t < 20.0; t += 0.01) {
    const Reference a = ref.next(t), b = copy->next(t);
    ASSERT_EQ(a.pose.x, b.pose.x);
    ASSERT_EQ(a.pose.y, b.pose.y);
    ASSERT_EQ(a.omega_dot, b.omega_dot);
  }
}

TEST(FieldPathReference, ThreeRowFieldIsSownClearOfTheObstacleToTheLastRowsEnd) {
  const FieldRunSetup s = threeRows();
  const FieldRunReport r = runField(s);
  std::printf("3-row field, path follower: %s\n", r.summary().c_str());
  EXPECT_FALSE(r.diverged);
  EXPECT_EQ(r.contacts, 0u);
  EXPECT_GT(r.min_clearance, 0.1);
  EXPECT_GT(r.rows.count, 400u);
  EXPECT_LT(r.rows.max, 0.02);
  EXPECT_NEAR(r.end.x(), 30.0 + s.field.run_out, 0.15);  // the tool point at the row end
  EXPECT_NEAR(r.end.y(), 5.0, 0.05);
}

TEST(FieldPathReference, ObstacleAddedAtRunTimeIsPlannedRoundFromTheRobotsProgress) {
  FieldRunSetup s = test::thesisField();
  s.field.follower = FieldFollower::kPath;
  s.obstacles = {};
  s.scenario.duration = 110.0 + approachExtraTime(s) + 20.0;  // the detour is slower than the row
  bool set = false;
  test::addObstacleAtRunTime(s, 20.0, {40.0, 3.0, 0.3}, set);  // the robot is near x = 20: 20 m ahead
  const FieldRunReport r = runField(s);
  std::printf("obstacle added at run time, path follower: %s\n", r.summary().c_str());
  ASSERT_TRUE(set);
  EXPECT_EQ(r.status.detours, 1u);
  EXPECT_EQ(r.contacts, 0u);
  EXPECT_LT(r.min_clearance, 1.0);                        // it did meet the obstacle
  EXPECT_NEAR(r.end.x(), 100.0 + s.field.run_out, 0.15);  // the tool point at the row end
  EXPECT_LT(r.rows.max, 0.02);
}

TEST(FieldPathReference, ApproachExtraTimeCoversTheFollowersSlowerCurves) {
  FieldRunSetup s = threeRows();
  FieldPathReference ref(withStart(s), s.obstacles);
  FieldParams plain = s.field;
  plain.approach = false;
  EXPECT_NEAR(approachExtraTime(s), ref.duration() - FieldPath(plain, s.obstacles).duration(), 1e-9);
  EXPECT_EQ(approachExtraTime(ref), approachExtraTime(s));  // from the reference built (the benchmark's rows)
  s.field.follower = FieldFollower::kPotential;
  EXPECT_LT(approachExtraTime(s), 5.0);  // the approach only
  EXPECT_EQ(approachExtraTime(FieldReference(withStart(s), s.obstacles)), approachExtraTime(s));
}

}  // namespace
}  // namespace core
}  // namespace sowing_robot
