#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/field_soil.h"

using sowing_robot::core::FieldParams;
using sowing_robot::core::FieldPath;
using sowing_robot::core::FieldReference;
using sowing_robot::core::HeadlandTurn;
using sowing_robot::core::Obstacle;
using sowing_robot::core::Reference;
using sowing_robot::core::wrapAngle;

namespace {

bool sameReference(const Reference& a, const Reference& b) {
  return a.pose.x == b.pose.x && a.pose.y == b.pose.y && a.pose.theta == b.pose.theta && a.v == b.v &&
         a.omega == b.omega && a.v_dot == b.v_dot && a.omega_dot == b.omega_dot && a.tool_down == b.tool_down;
}

FieldParams threeRows(double spacing) {
  FieldParams p;
  p.rows = 3;
  p.row_length = 12.0;
  p.row_spacing = spacing;
  p.start_x = 1.0;
  p.start_y = -2.0;
  p.heading = 0.4;
  p.row_speed = 1.0;
  p.turn_speed = 0.4;
  p.min_turn_radius = 0.5;
  p.max_accel = 0.5;
  return p;
}

struct Limits {
  double max_turn_speed = 0.0, max_turn_curvature = 0.0, max_speed = 0.0, max_accel = 0.0;
  double max_omega_step = 0.0, max_vdot_step = 0.0;  ///< largest change between two 1 ms samples
  int turn_samples = 0, row_samples = 0;
  bool finished = false;
  Reference last;
};

/// Sample the reference every 1 ms until 2 s after the end.
Limits sampleField(FieldReference& f) {
  Limits l;
  const int n = static_cast<int>((f.duration() + 2.0) * 1e3);
  Reference prev;
  for (int k = 0; k <= n; ++k) {
    const double t = k * 1e-3;
    const Reference r = f.next(t);
    if (!r.tool_down && !f.finished(t)) {
      ++l.turn_samples;
      l.max_turn_speed = std::max(l.max_turn_speed, r.v);
      l.max_turn_curvature = std::max(l.max_turn_curvature, std::fabs(r.omega) / r.v);
    }
    if (r.tool_down) ++l.row_samples;
    l.max_speed = std::max(l.max_speed, r.v);
    l.max_accel = std::max(l.max_accel, std::fabs(r.v_dot));
    if (k > 0) {
      l.max_omega_step = std::max(l.max_omega_step, std::fabs(r.omega - prev.omega));
      l.max_vdot_step = std::max(l.max_vdot_step, std::fabs(r.v_dot - prev.v_dot));
    }
    prev = r;
  }
  l.finished = f.finished(n * 1e-3);
  l.last = prev;
  return l;
}

}  // namespace

TEST(FieldParams, ValidateNamesTheBadParameter) {
  EXPECT_EQ(FieldParams{}.validate(), "");
  auto bad = [](auto mutate, const std::string& name) {
    FieldParams p;
    p.rows = 3;
    mutate(p);
    const std::string e = p.validate();
    EXPECT_NE(e.find(name), std::string::npos) << name << ": " << e;
    EXPECT_THROW(FieldReference{p}, std::invalid_argument);
  };
  bad([](FieldParams& p) { p.rows = 0; }, "rows");
  bad([](FieldParams& p) { p.row_length = 0.0; }, "row_length");
  bad([](FieldParams& p) { p.row_spacing = -1.0; }, "row_spacing");
  bad([](FieldParams& p) { p.row_speed = 0.0; }, "row_speed");
  bad([](FieldParams& p) { p.turn_speed = 0.0; }, "turn_speed");
  bad([](FieldParams& p) { p.turn_speed = 1.5; }, "turn_speed");
  bad([](FieldParams& p) { p.min_turn_radius = 0.0; }, "min_turn_radius");
  bad([](FieldParams& p) { p.max_accel = 0.0; }, "max_accel");
  bad([](FieldParams& p) { p.max_curvature_rate = 1.0; }, "max_curvature_rate");
  bad([](FieldParams& p) { p.start_y = std::nan(""); }, "start");
  bad([](FieldParams& p) { p.potential.beta = 0.0; }, "beta");
  bad([](FieldParams& p) { p.row_length = 0.5; }, "row_length");  // too short to slow down for the turn
  EXPECT_THROW(FieldReference(FieldParams{}, {{1.0, 1.0, 0.0}}), std::invalid_argument);
}

TEST(HeadlandTurn, EndsOneSpacingAsideWithReversedHeadingWithinLimits) {
  const double kmax = 2.0, rate = 10.0;
  for (const double w : {0.1, 0.5, 0.75, 1.0, 1.2, 2.0, 6.0}) {
    const HeadlandTurn turn(w, kmax, rate);
    Eigen::Vector2d p;
    double th, k, dk;
    turn.evaluate(turn.length(), p, th, k, dk);
    EXPECT_NEAR(p.x(), 0.0, 1e-9) << w;
    EXPECT_NEAR(p.y(), w, 1e-9) << w;
    EXPECT_NEAR(th, M_PI, 1e-12) << w;
    EXPECT_NEAR(k, 0.0, 1e-12) << w;
    // Curvature and its rate bounded, heading consistent with the positions, curvature continuous.
    const int n = 20000;
    Eigen::Vector2d prev = Eigen::Vector2d::Zero();
    double prev_k = 0.0, prev_th = 0.0;
    const double ds = turn.length() / n;
    for (int i = 1; i <= n; ++i) {
      turn.evaluate(i * ds, p, th, k, dk);
      ASSERT_LE(std::fabs(k), kmax * (1.0 + 1e-12));
      ASSERT_LE(std::fabs(dk), rate * (1.0 + 1e-12));
      ASSERT_LE(std::fabs(k - prev_k), rate * ds * 1.0001);
      const Eigen::Vector2d chord = p - prev;
      ASSERT_NEAR(chord.norm(), ds, 1e-6 * ds);  // chord vs arc: ds^3 kappa^2 / 24
      ASSERT_NEAR(std::atan2(chord.y(), chord.x()), wrapAngle(0.5 * (th + prev_th)), 1e-6);
      prev = p;
      prev_k = k;
      prev_th = th;
    }
    EXPECT_EQ(turn.isBulb(), w < 1.0 + 0.1) << w;  // 2 R_min = 1 m plus the ramps' widening
  }
  // A wide turn is a semicircle-like arc whose radius approaches w/2.
  const HeadlandTurn wide(6.0, kmax, rate);
  EXPECT_NEAR(wide.peakCurvature(), 2.0 / 6.0, 0.01);
  EXPECT_THROW(HeadlandTurn(0.0, kmax, rate), std::invalid_argument);
}

TEST(FieldReference, ThreeRowFieldRespectsTurnLimitsAndFinishes) {
  for (const double spacing : {0.75, 2.0}) {  // bulb turns and rounded semicircles
    for (const bool left : {true, false}) {
      FieldParams p = threeRows(spacing);
      p.rows_to_left = left;
      FieldReference f(p);
      const Limits l = sampleField(f);
      const double tol = 1e-9;
      EXPECT_GT(l.turn_samples, 1000);
      EXPECT_LE(l.max_turn_speed, p.turn_speed + tol);
      EXPECT_LE(l.max_turn_curvature, 1.0 / p.min_turn_radius + 1e-6);
      EXPECT_LE(l.max_speed, p.row_speed + tol);
      EXPECT_LE(l.max_accel, p.max_accel + tol);
      // Smooth: no steps in omega or v_dot between 1 ms samples.
      EXPECT_LT(l.max_omega_step, 0.01);
      EXPECT_LT(l.max_vdot_step, 0.01);
      EXPECT_TRUE(l.finished);
      // Stopped at the end of the third row (it runs along the heading again).
      const Eigen::Vector2d end =
          f.path().rowStart(2) + p.row_length * Eigen::Vector2d(std::cos(p.heading), std::sin(p.heading));
      EXPECT_NEAR(l.last.pose.x, end.x(), 1e-9);
      EXPECT_NEAR(l.last.pose.y, end.y(), 1e-9);
      EXPECT_NEAR(wrapAngle(l.last.pose.theta - p.heading), 0.0, 1e-9);
      EXPECT_EQ(l.last.v, 0.0);
      EXPECT_FALSE(l.last.tool_down);
      const Eigen::Vector2d side = (left ? 1.0 : -1.0) * Eigen::Vector2d(-std::sin(p.heading), std::cos(p.heading));
      EXPECT_NEAR((f.path().rowStart(2) - f.path().rowStart(0)).dot(side), 2.0 * spacing, 1e-12);
    }
  }
}

TEST(FieldReference, RowsAreFollowedExactlyWithTheToolDown) {
  FieldParams p = threeRows(1.5);
  FieldReference f(p);
  const Eigen::Vector2d u(std::cos(p.heading), std::sin(p.heading)), n(-u.y(), u.x());
  for (int k = 0; k <= static_cast<int>(f.duration() * 1e3); ++k) {
    const double t = k * 1e-3;
    const Reference r = f.next(t);
    const Eigen::Vector2d q = Eigen::Vector2d(r.pose.x, r.pose.y) - f.path().rowStart(0);
    const double lateral = q.dot(n), along = q.dot(u);
    if (r.tool_down) {
      // On a row: on one of the three lines, inside its length, heading along or against it.
      const double row = std::round(lateral / p.row_spacing);
      ASSERT_NEAR(lateral, row * p.row_spacing, 1e-9) << t;
      ASSERT_GE(along, -1e-9);
      ASSERT_LE(along, p.row_length + 1e-9);
      const double expected = p.heading + (static_cast<int>(row) % 2 == 1 ? M_PI : 0.0);
      ASSERT_NEAR(wrapAngle(r.pose.theta - expected), 0.0, 1e-9) << t;
      ASSERT_NEAR(r.omega, 0.0, 1e-9);
    } else if (!f.finished(t)) {
      // In the headland: beyond the row ends.
      ASSERT_TRUE(along >= p.row_length - 1e-9 || along <= 1e-9) << t << " along " << along;
    }
  }
}

TEST(FieldReference, DerivativesAreConsistentOnTurnsAndSpeedRamps) {
  FieldParams p = threeRows(0.6);
  FieldReference f(p);
  const double delta = 1e-5;
  int checked = 0;
  for (int k = 0; k + 1 < static_cast<int>(f.duration() * 1e3); k += 11) {
    const double t = (k + 0.5) * 1e-3;
    const Reference a = f.next(t - delta), r = f.next(t), b = f.next(t + delta);
    EXPECT_NEAR(r.omega, wrapAngle(b.pose.theta - a.pose.theta) / (2.0 * delta), 1e-6) << t;
    EXPECT_NEAR(r.v, std::hypot(b.pose.x - a.pose.x, b.pose.y - a.pose.y) / (2.0 * delta), 1e-6) << t;
    EXPECT_NEAR(r.v_dot, (b.v - a.v) / (2.0 * delta), 1e-6) << t;
    EXPECT_NEAR(r.omega_dot, (b.omega - a.omega) / (2.0 * delta), 1e-5) << t;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

TEST(FieldReference, ThesisScenarioWithThreeObstaclesReachesTheEnd) {
  // One 100 m row at y = 3 from x = 0 heading 0 at 1 m/s; obstacles at (20,3), (50,3), (80,3).
  FieldParams p;
  p.rows = 1;
  p.row_length = 100.0;
  p.start_x = 0.0;
  p.start_y = 3.0;
  p.heading = 0.0;
  p.row_speed = 1.0;
  const std::vector<Obstacle> obs{{20.0, 3.0, 0.3}, {50.0, 3.0, 0.3}, {80.0, 3.0, 0.3}};
  FieldReference f(p, obs);
  double min_clearance = std::numeric_limits<double>::infinity(), max_dev = 0.0;
  Reference r;
  const int n = static_cast<int>((f.duration() + 5.0) * 1e3);
  for (int k = 0; k <= n; ++k) {
    r = f.next(k * 1e-3);
    min_clearance = std::min(min_clearance, f.potentialField().minObstacleClearance({r.pose.x, r.pose.y}));
    max_dev = std::max(max_dev, std::fabs(r.pose.y - 3.0));
  }
  EXPECT_GT(max_dev, 0.3);  // it did go around
  EXPECT_GT(min_clearance, 0.1);
  EXPECT_TRUE(f.finished(n * 1e-3));
  // 5 s after the target stopped at (100, 3) the reference is there to 1 cm (the last obstacle is only
  // 20 m before the end; the slow mode of alpha = 4, beta = 16 decays as exp(-0.25 t)) and still closing.
  EXPECT_NEAR(r.pose.x, 100.0, 1e-2);
  EXPECT_NEAR(r.pose.y, 3.0, 1e-2);
  EXPECT_LT(r.v, 1e-2);
  const Reference later = f.next(f.duration() + 40.0);
  EXPECT_NEAR(later.pose.x, 100.0, 1e-5);
  EXPECT_NEAR(later.pose.y, 3.0, 1e-5);
}

TEST(FieldReference, ObstacleOnAMiddleRowIsAvoidedAndTheFieldFinishes) {
  FieldParams p = threeRows(1.5);
  p.row_length = 40.0;
  FieldReference f(p);
  const Eigen::Vector2d u(std::cos(p.heading), std::sin(p.heading));
  const Eigen::Vector2d c = f.path().rowStart(1) - 15.0 * u;  // 15 m into the second row
  f.setObstacles({{c.x(), c.y(), 0.3}});
  double min_clearance = 1e9, max_dev = 0.0;
  Reference r;
  for (int k = 0; k <= static_cast<int>((f.duration() + 5.0) * 1e3); ++k) {
    r = f.next(k * 1e-3);
    const Eigen::Vector2d q(r.pose.x, r.pose.y);
    min_clearance = std::min(min_clearance, f.potentialField().minObstacleClearance(q));
    max_dev = std::max(max_dev, (q - c).norm() < 1.5 ? std::fabs((q - c).dot(Eigen::Vector2d(-u.y(), u.x()))) : 0.0);
  }
  EXPECT_GT(min_clearance, 0.1);
  EXPECT_GT(max_dev, 0.3);
  const Eigen::Vector2d end = f.path().rowStart(2) + p.row_length * u;
  EXPECT_NEAR(r.pose.x, end.x(), 1e-6);
  EXPECT_NEAR(r.pose.y, end.y(), 1e-6);
}

TEST(FieldReference, StartFromRest) {
  FieldParams p = threeRows(1.0);
  p.start_from_rest = true;
  FieldReference f(p);
  const Reference r0 = f.next(0.0);
  EXPECT_EQ(r0.v, 0.0);
  EXPECT_NEAR(r0.pose.theta, p.heading, 1e-15);
  EXPECT_NEAR(r0.pose.x, p.start_x, 1e-15);
  const Reference r1 = f.next(1.0);
  EXPECT_GT(r1.v, 0.1);
  EXPECT_NEAR(r1.pose.theta, p.heading, 1e-12);
  const Limits l = sampleField(f);
  EXPECT_LE(l.max_accel, p.max_accel + 1e-9);
  EXPECT_TRUE(l.finished);
}

TEST(FieldReference, CloneAndDeterminism) {
  FieldParams p = threeRows(0.75);
  const std::vector<Obstacle> obs{{4.0, -0.4, 0.3}};
  FieldReference a(p, obs), b(p, obs);
  for (int k = 0; k < 5000; ++k) a.next(k * 1e-3);
  auto c = a.clone();  // reset state
  a.reset();
  std::vector<double> ts;
  for (double t = 0.0; t < a.duration() + 1.0; t += (ts.size() % 4 == 0 ? 0.0173 : 0.001)) ts.push_back(t);
  for (double t : ts) {
    const Reference rc = c->next(t);
    const Reference ra = a.next(t);
    ASSERT_TRUE(sameReference(ra, b.next(t))) << t;
    ASSERT_TRUE(sameReference(ra, rc)) << t;
  }
}

// A soil patch wholly outside the rows and their headlands is a warning naming it (not an error: the map describes
// the ground, and one map may serve a smaller field); one on the rows or on a headland is not.
TEST(FieldSoil, PatchesWhollyOutsideTheFieldAreNamed) {
  namespace core = sowing_robot::core;
  FieldParams f;
  f.rows = 3;
  f.row_length = 20.0;
  f.row_spacing = 1.0;
  f.start_x = 0.0;
  f.start_y = 3.0;
  f.heading = 0.0;
  f.rows_to_left = true;
  f.min_turn_radius = 1.0;  // margin max(1, 2) = 2 m
  const auto patch = [](double x0, double y0, double x1, double y1) {
    core::SoilPatch p;
    p.polygon = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    return p;
  };
  EXPECT_EQ(core::patchesOutsideField(f, {patch(5, 2, 8, 6)}), "");  // on the rows
  EXPECT_EQ(core::patchesOutsideField(f, {patch(20.5, 0, 21.5, 8)}),
            "");  // on the headland past the rows' ends
  const std::string w =
      core::patchesOutsideField(f, {patch(5, 2, 8, 6), patch(100, 100, 110, 110), patch(-5, -5, -3, -3)});
  EXPECT_EQ(w.rfind("field/patches[1], field/patches[2] lie(s) wholly outside the field's rows", 0), 0u) << w;
  const std::vector<Eigen::Vector2d> ground = core::fieldGround(f);
  ASSERT_EQ(ground.size(), 4u);
  EXPECT_NEAR(ground[0].x(), -2.0, 1e-12);
  EXPECT_NEAR(ground[0].y(), 1.0, 1e-12);
  EXPECT_NEAR(ground[2].x(), 22.0, 1e-12);
  EXPECT_NEAR(ground[2].y(), 7.0, 1e-12);
}

namespace {
/// The seed drill's tool point, `run_out` behind the axle's target along its heading.
Eigen::Vector2d toolPoint(const sowing_robot::core::TargetState& s, double run_out) {
  return s.p - run_out * sowing_robot::core::unitVector(s.heading);
}
/// Along-row position and lateral offset of p from row i of `path` (row i runs from rowStart(i) along heading_i).
void rowFrame(const FieldPath& path, const FieldParams& f, int i, const Eigen::Vector2d& p, double& along,
              double& lateral) {
  const Eigen::Vector2d u = sowing_robot::core::unitVector(f.heading + (i % 2 == 1 ? M_PI : 0.0));
  const Eigen::Vector2d d = p - path.rowStart(i);
  along = d.dot(u);
  lateral = u.x() * d.y() - u.y() * d.x();
}
}  // namespace

// With a plan, every row is driven on by run_out past its end: the headland turn starts when the tool point, which
// trails the axle by run_out, is at the row's end on its line; the turn ends run_out before the next row's start, so
// the tool point comes onto that row on its line. The thesis path (no plan) turns at the axle's row end.
TEST(FieldPath, WithAPlanTheToolPointIsOnTheRowLineAtEachRowsEndAndStart) {
  for (const double spacing : {1.5, 0.75}) {  // rounded and bulb turns
    FieldParams f = threeRows(spacing);
    f.run_out = 0.45;
    const FieldPath path(f);
    int ends = 0, starts = 0;
    bool was_turn = false;
    int row = 0;
    double first_down_along = std::numeric_limits<double>::quiet_NaN();
    for (double t = 0.0; t <= path.duration(); t += 1e-3) {
      const bool turn = path.onTurn(t);
      const sowing_robot::core::TargetState st = path.at(t);
      const Eigen::Vector2d tool = toolPoint(st, f.run_out);
      double along, lateral;
      if (turn && !was_turn) {  // the turn starts: the tool point at the row's end, on its line
        rowFrame(path, f, row, tool, along, lateral);
        EXPECT_NEAR(along, f.row_length, 2e-3) << "row " << row << " spacing " << spacing;
        EXPECT_NEAR(lateral, 0.0, 1e-9) << "row " << row;
        ++ends;
        ++row;
      }
      if (!turn && was_turn) {  // the turn ends run_out before the next row's start, heading along it
        rowFrame(path, f, row, st.p, along, lateral);
        EXPECT_NEAR(along, -f.run_out, 2e-3) << "row " << row << " spacing " << spacing;
        EXPECT_NEAR(lateral, 0.0, 1e-9) << "row " << row;
        ++starts;
      }
      if (!turn && row > 0) {  // from the turn's end the axle and the tool point are on the row's line
        rowFrame(path, f, row, tool, along, lateral);
        EXPECT_NEAR(lateral, 0.0, 1e-9) << "row " << row << " t " << t;
        if (std::isnan(first_down_along) && row == 1 && st.tool_down) first_down_along = along;
      }
      was_turn = turn;
    }
    EXPECT_EQ(ends, 2);
    EXPECT_EQ(starts, 2);
    // The tool is asked for from the row's start (the axle's), while the tool point is still behind it.
    EXPECT_NEAR(first_down_along, -f.run_out, 2e-3);
    // The last row ends at rest with the tool point at its end.
    double along, lateral;
    rowFrame(path, f, 2, toolPoint(path.at(path.duration() + 1.0), f.run_out), along, lateral);
    EXPECT_NEAR(along, f.row_length, 1e-9);
    EXPECT_NEAR(lateral, 0.0, 1e-9);
    // Each of the two turns adds 2 run_out of row, the last row's end one more.
    FieldParams thesis = f;
    thesis.avoidance.plan_detours = false;
    EXPECT_NEAR(path.length() - FieldPath(thesis).length(), 5.0 * f.run_out, 1e-9);
  }
}

// The thesis path (no plan) is the thesis's whatever run_out: the turns start at the axle's row end.
TEST(FieldPath, WithoutAPlanTheRunOutChangesNothing) {
  FieldParams f = threeRows(1.5);
  f.avoidance.plan_detours = false;
  const FieldPath plain(f);
  f.run_out = 0.45;
  const FieldPath with(f);
  EXPECT_EQ(plain.duration(), with.duration());
  for (double t = 0.0; t < plain.duration() + 1.0; t += 0.013) {
    EXPECT_EQ(plain.at(t).p, with.at(t).p);
    EXPECT_EQ(plain.at(t).tool_down, with.at(t).tool_down);
  }
}

// The approach joins the first row's line approach_settle + run_out before its start (where it fits): the tool is
// asked for before the tool point reaches the row's start, with the tool point on the line.
TEST(FieldPath, TheApproachSettlesBeforeTheFirstRowsStart) {
  FieldParams f = threeRows(1.5);
  f.run_out = 0.45;
  const Eigen::Vector2d u = sowing_robot::core::unitVector(f.heading), n(-u.y(), u.x());
  const Eigen::Vector2d s = Eigen::Vector2d(f.start_x, f.start_y) - 6.0 * u + 0.4 * n;
  f.start_pose = sowing_robot::core::Pose2D{s.x(), s.y(), f.heading - 0.2};
  const FieldPath path(f);
  ASSERT_TRUE(path.hasApproach());
  bool reached = false;
  for (double t = 0.0; t < 20.0 && !reached; t += 1e-3) {
    const sowing_robot::core::TargetState st = path.at(t);
    double along, lateral;
    rowFrame(path, f, 0, toolPoint(st, f.run_out), along, lateral);
    if (along < 0.0) continue;
    reached = true;
    EXPECT_TRUE(st.tool_down) << "t " << t;
    EXPECT_NEAR(lateral, 0.0, 1e-9);
  }
  EXPECT_TRUE(reached);
}
