// The approach, the first seconds: the field's target starts at the robot's start pose and joins the first
// row on an approach within the detours' bounds (approach.h), so the whole run, not only the rows,
// keeps the yaw rate and the lateral acceleration within them.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sowing_robot/core/simulation/field_run.h"
#include "thesis_field_fixture.h"

using namespace sowing_robot::core;

namespace {

using test::thesisField;  // config/field_thesis.yaml's closed loop; peaks over the whole run

FieldParams withStart(FieldParams f, Pose2D start) {
  f.start_pose = start;
  return f;
}

/// Curvature of the target's path at t (|v x a| / |v|^3, signed) [1/m].
double curvature(const TargetState& s) {
  const double v = s.v.norm();
  return (s.v.x() * s.a.y() - s.v.y() * s.a.x()) / (v * v * v);
}

/// Samples the approach of `path` every 1 ms: its curvature stays within max_curvature and the yaw rate
/// and v omega within the bounds less the tracking reserve, and the curvature moves by no more than
/// max_curvature_rate times the distance covered (continuous).
void expectApproachWithinBounds(const FieldPath& path, const FieldParams& f) {
  ASSERT_TRUE(path.hasApproach());
  const double keep = 1.0 - f.avoidance.tracking_reserve;
  const double dt = 1e-3;
  double t_join = 0.0;
  while (t_join < path.duration() && !path.at(t_join).tool_down && t_join < 60.0) t_join += dt;
  ASSERT_GT(t_join, 0.5);
  double k_last = curvature(path.at(0.0)), peak_k = 0.0;
  EXPECT_NEAR(k_last, 0.0, 1e-9);  // the start: not turning
  for (double t = dt; t <= t_join; t += dt) {
    const TargetState s = path.at(t);
    const double k = curvature(s), v = s.v.norm();
    EXPECT_LE(std::fabs(k), f.avoidance.max_curvature * (1.0 + 1e-6)) << "t " << t;
    EXPECT_LE(v * std::fabs(k), keep * f.avoidance.max_yaw_rate * (1.0 + 1e-3)) << "t " << t;
    EXPECT_LE(v * v * std::fabs(k), keep * f.avoidance.max_lateral_accel * (1.0 + 1e-3)) << "t " << t;
    EXPECT_LE(std::fabs(k - k_last), f.max_curvature_rate * v * dt * 1.01 + 1e-9) << "t " << t;
    peak_k = std::max(peak_k, std::fabs(k));
    k_last = k;
  }
  EXPECT_GT(peak_k, 0.1);  // it did turn
}

}  // namespace

TEST(Approach, ThesisFieldWholeRunWithinTheBoundsWithoutContactAndKeepsTheRowSeeds) {
  const FieldRunSetup s = thesisField();
  const FieldRunReport r = runField(s);
  std::printf("thesis field, whole run: %s\n", r.summary().c_str());
  EXPECT_FALSE(r.diverged);
  EXPECT_EQ(r.contacts, 0u) << r.summary();
  EXPECT_GE(r.min_clearance, s.field.avoidance.safety_margin) << r.summary();
  EXPECT_LE(r.peak_yaw_rate, s.field.avoidance.max_yaw_rate) << r.summary();
  EXPECT_LE(r.peak_lateral, s.field.avoidance.max_lateral_accel) << r.summary();
  EXPECT_LE(r.peak_ref_yaw_rate, s.field.avoidance.max_yaw_rate) << r.summary();
  EXPECT_LE(r.peak_ref_lateral, s.field.avoidance.max_lateral_accel) << r.summary();
  EXPECT_TRUE(r.status.within_bounds) << r.status.bounds_note;
  EXPECT_EQ(r.status.code, AvoidanceStatus::Code::kOk);
  EXPECT_NEAR(r.end.x(), 100.0 + s.field.run_out, 0.15);  // the tool point at the row end
  EXPECT_NEAR(r.end.y(), 3.0, 0.05);
  // The approach sows nothing; the rows' seeds no worse than with the thesis potential field (max 7.8 mm, RMS 1.6 mm).
  EXPECT_GT(r.rows.count, 600u);
  EXPECT_LE(r.rows.max, 7.8e-3);
  EXPECT_LE(r.rows.rms, 1.6e-3);

  // What the approach protects: without it the target starts on the row, 3 m from the robot, and the
  // controllers close that at once (4.35 rad/s, 3.61 m/s^2).
  FieldRunSetup without = s;
  without.field.approach = false;
  const FieldRunReport w = runField(without);
  EXPECT_GT(w.peak_yaw_rate, 2.0 * s.field.avoidance.max_yaw_rate) << w.summary();
  EXPECT_GT(w.peak_lateral, 2.0 * s.field.avoidance.max_lateral_accel) << w.summary();
}

TEST(Approach, StartsAtTheStartPoseAndJoinsTheRowWithContinuousBoundedCurvature) {
  const FieldRunSetup s = thesisField();
  for (const Pose2D start :
       {Pose2D{-1.0, 0.0, 0.0}, Pose2D{-1.0, 0.0, 0.6}, Pose2D{-4.0, 6.0, -0.4}, Pose2D{2.0, 2.5, 0.3}}) {
    SCOPED_TRACE("start (" + std::to_string(start.x) + ", " + std::to_string(start.y) + ", " +
                 std::to_string(start.theta) + ")");
    const FieldParams f = withStart(s.field, start);
    const FieldPath path(f, s.obstacles);
    EXPECT_TRUE(path.status().within_bounds) << path.status().bounds_note;
    const TargetState t0 = path.at(0.0);
    EXPECT_NEAR(t0.p.x(), start.x, 1e-9);
    EXPECT_NEAR(t0.p.y(), start.y, 1e-9);
    EXPECT_NEAR(t0.heading, start.theta, 1e-9);
    EXPECT_FALSE(t0.tool_down);
    expectApproachWithinBounds(path, f);
    // Joined: on the row line, along it, and sowing from there on.
    const ApproachCurve& c = path.approach().curve;
    Eigen::Vector2d p;
    double th, k, dk;
    c.evaluate(c.length(), p, th, k, dk);
    EXPECT_NEAR(p.y(), 3.0, 1e-9);
    EXPECT_NEAR(th, 0.0, 1e-9);
    EXPECT_NEAR(k, 0.0, 1e-9);
    EXPECT_GE(p.x(), -(s.field.approach_settle + s.field.run_out) - 1e-9);  // at the earliest this far before the start
    EXPECT_LT(p.x(), 20.0 - 0.3 - s.field.avoidance.pathClearance(0.5));    // before the first detour
  }
}

TEST(Approach, NoneFromAStartOnTheRowNorWithoutAPlanNorWhenSwitchedOff) {
  const FieldRunSetup s = thesisField();
  const FieldPath plain(s.field, s.obstacles);  // no start pose: the path of before the approach
  auto samePath = [&](const FieldParams& f) {
    const FieldPath path(f, s.obstacles);
    EXPECT_FALSE(path.hasApproach());
    EXPECT_EQ(path.duration(), plain.duration());
    for (double t = 0.0; t < plain.duration(); t += 0.37) {
      const TargetState a = path.at(t), b = plain.at(t);
      EXPECT_EQ(a.p, b.p);
      EXPECT_EQ(a.v, b.v);
      EXPECT_EQ(a.a, b.a);
      EXPECT_EQ(a.tool_down, b.tool_down);
    }
  };
  samePath(withStart(s.field, Pose2D{0.0, 3.0, 0.0}));        // already on the row, at its start
  samePath(withStart(s.field, Pose2D{0.0005, 3.0, 0.0005}));  // within 1 mm and 1 mrad of it
  FieldParams off = withStart(s.field, Pose2D{-1.0, 0.0, 0.0});
  off.approach = false;
  samePath(off);
  FieldParams thesis = withStart(s.field, Pose2D{-1.0, 0.0, 0.0});
  thesis.avoidance.plan_detours = false;  // the thesis potential field, unchanged
  const FieldPath a(thesis, s.obstacles);
  FieldParams thesis_plain = s.field;
  thesis_plain.avoidance.plan_detours = false;
  const FieldPath b(thesis_plain, s.obstacles);
  EXPECT_FALSE(a.hasApproach());
  for (double t = 0.0; t < b.duration(); t += 0.37) EXPECT_EQ(a.at(t).p, b.at(t).p);
}

TEST(Approach, StartBehindTheRowOnItsLineDrivesStraightOnAndLowersTheToolAfterTheSettleDistance) {
  const FieldRunSetup s = thesisField();
  const FieldPath path(withStart(s.field, Pose2D{-3.0, 3.0, 0.0}), s.obstacles);
  ASSERT_TRUE(path.hasApproach());
  // It joins the row's line approach_settle + run_out before the row's start (the curve counts from there), so the
  // tool is asked for settle past the join, run_out before the row's start: before the tool point, run_out behind
  // the axle, reaches the row.
  const double lead = s.field.approach_settle + s.field.run_out;
  EXPECT_GT(s.field.run_out, 0.4);
  EXPECT_NEAR(path.approach().curve.joinAlong(), 0.0, 1e-12);
  EXPECT_NEAR(path.approach().curve.length(), 3.0 - lead, 1e-9);
  for (double t = 0.0; t < 10.0; t += 1e-3) {
    const TargetState st = path.at(t);
    EXPECT_NEAR(st.p.y(), 3.0, 1e-12);
    EXPECT_EQ(st.tool_down, st.p.x() >= s.field.approach_settle - lead) << "t " << t << " x " << st.p.x();
  }
}

TEST(Approach, ImpossibleApproachesStartAtTheRowStartAndSaySo) {
  const FieldRunSetup s = thesisField();
  // Facing away from the row, and an obstacle in the way.
  std::vector<std::pair<Pose2D, std::vector<Obstacle>>> cases = {
      {Pose2D{-1.0, 0.0, 3.0}, s.obstacles},
      {Pose2D{-1.0, 0.0, 0.0}, {{1.0, 1.5, 0.3}, {20.0, 3.0, 0.3}}},
      {Pose2D{30.0, 0.0, 0.0}, s.obstacles},  // past the first obstacle: no room before its detour
  };
  for (const auto& [start, obstacles] : cases) {
    const FieldPath path(withStart(s.field, start), obstacles);
    EXPECT_FALSE(path.hasApproach());
    EXPECT_TRUE(path.approach().needed);
    EXPECT_FALSE(path.status().within_bounds);
    EXPECT_NE(path.status().bounds_note.find("no approach"), std::string::npos) << path.status().bounds_note;
    EXPECT_NEAR(path.at(0.0).p.x(), 0.0, 1e-12);
    EXPECT_NEAR(path.at(0.0).p.y(), 3.0, 1e-12);
  }
}

TEST(Approach, ParametersComeFromTheTable) {
  const FieldParams f;
  EXPECT_TRUE(f.approach);
  EXPECT_DOUBLE_EQ(f.approach_settle, 1.0);
  EXPECT_FALSE(f.start_pose.has_value());
  FieldParams bad;
  bad.approach_settle = -1.0;
  EXPECT_NE(bad.validate(), "");
  FieldParams nan;
  nan.start_pose = Pose2D{std::nan(""), 0.0, 0.0};
  EXPECT_NE(nan.validate().find("start pose"), std::string::npos);
}
