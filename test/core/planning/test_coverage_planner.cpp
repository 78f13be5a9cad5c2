// The coverage planner (coverage_planner.h) and its figures (coverage_metrics.h): today's rectangular field as
// one case of it, an L-shaped hectare with two voids, a void that splits the inner field, the edges' one-line
// errors, and the route driven by the path follower.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "sowing_robot/core/planning/coverage_follower.h"
#include "sowing_robot/core/planning/coverage_metrics.h"
#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/path_plan.h"
#include "sowing_robot/core/planning/seeding.h"

using namespace sowing_robot::core;

namespace {

Ring rectangle(double x0, double y0, double x1, double y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

Ring rotated(const Ring& r, double angle) {
  Ring out;
  for (const Eigen::Vector2d& p : r) out.push_back(Eigen::Rotation2Dd(angle) * p);
  return out;
}

/// config/field.yaml's drill and turns: one row per pass, 1 m apart, min_turn_radius 0.5 m, rate 10 1/m^2.
CoverageParams fieldYamlParams() {
  CoverageParams p;
  p.rows_per_pass = 1;
  p.row_spacing = 1.0;
  p.headland_passes = 2;
  p.min_turn_radius = 0.5;
  p.max_curvature_rate = 10.0;
  return p;
}

/// The L-shaped hectare (140 x 50 m and 60 x 50 m) with a pond (a quadrilateral) and a tree (a circle).
FieldBoundary lShapedHectare() {
  FieldBoundary f;
  f.outer = {{0, 0}, {140, 0}, {140, 50}, {60, 50}, {60, 100}, {0, 100}};
  f.voids = {{{20, 20}, {35, 18}, {38, 32}, {22, 35}}};
  f.circles = {Obstacle{100.0, 25.0, 3.0}};
  return f;
}

/// Same line, either direction.
bool sameLine(const RowSegment& a, const RowSegment& b, double tol) {
  return ((a.a - b.a).norm() < tol && (a.b - b.b).norm() < tol) ||
         ((a.a - b.b).norm() < tol && (a.b - b.a).norm() < tol);
}

/// Largest curvature of the circle through three consecutive points of the route (Menger curvature).
double peakPointCurvature(const std::vector<Eigen::Vector2d>& pts) {
  double peak = 0.0;
  for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
    const Eigen::Vector2d a = pts[i] - pts[i - 1], b = pts[i + 1] - pts[i], c = pts[i + 1] - pts[i - 1];
    const double denom = a.norm() * b.norm() * c.norm();
    if (denom > 0.0) peak = std::max(peak, 2.0 * std::fabs(a.x() * b.y() - a.y() * b.x()) / denom);
  }
  return peak;
}

std::string errorOf(const FieldBoundary& f, const CoverageParams& p) {
  try {
    planCoverage(f, p);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// Today's field (3 rows of 30 m, 1 m apart from (0, 3)) inside a rectangle with two headland passes of room:
// the planner's swath rows are rowsOf(FieldParams), whether one row per pass or all three in one pass, and at
// any heading (to 10 um: Boost's offset of a rotated rectangle is off by 3 um).
TEST(CoveragePlanner, TodaysRectangularFieldIsOneCase) {
  for (const double heading : {0.0, 0.3}) {
    for (const int rows_per_pass : {1, 3}) {
      FieldParams field;
      field.rows = 3;
      field.row_length = 30.0;
      field.row_spacing = 1.0;
      field.start_x = 0.0;
      field.start_y = 3.0;
      field.heading = heading;
      const std::vector<RowSegment> today = rowsOf(field);

      CoverageParams p = fieldYamlParams();
      p.rows_per_pass = rows_per_pass;
      p.heading = std::to_string(heading);
      const double room = p.headland_passes * p.workingWidth();
      FieldBoundary f;
      // The rows' strip (across from -0.5 to 2.5 m of the first row) with the headland room round it, in the
      // rows' frame: from the first row's start, along its heading.
      for (const Eigen::Vector2d& q : rotated(rectangle(-room, -0.5 - room, 30.0 + room, 2.5 + room), heading))
        f.outer.push_back(q + Eigen::Vector2d(field.start_x, field.start_y));
      const CoveragePlan plan = planCoverage(f, p);
      std::vector<RowSegment> rows = plan.rows();
      rows.resize(plan.swathRows());  // the swaths' rows; the headland rows follow them
      ASSERT_EQ(rows.size(), today.size()) << "heading " << heading << ", rows per pass " << rows_per_pass;
      for (const RowSegment& r : today)
        EXPECT_TRUE(std::any_of(rows.begin(), rows.end(), [&](const RowSegment& q) { return sameLine(q, r, 1e-5); }))
            << "row from (" << r.a.transpose() << ") to (" << r.b.transpose() << ") is not planned";
      EXPECT_EQ(plan.swaths.size(), static_cast<std::size_t>(3 / rows_per_pass));
      EXPECT_EQ(plan.parts, 1);
      if (rows_per_pass == 1) {
        // Driven as today: the first row from its start, then alternating.
        for (std::size_t i = 0; i < rows.size(); ++i) {
          EXPECT_LT((rows[i].a - today[i].a).norm(), 1e-5) << i;
          EXPECT_LT((rows[i].b - today[i].b).norm(), 1e-5) << i;
        }
      }
    }
  }
}

TEST(CoveragePlanner, LShapedHectareWithTwoVoidsIsCoveredWithinItsTurnBounds) {
  const FieldBoundary f = lShapedHectare();
  const CoverageParams p = fieldYamlParams();
  const CoveragePlan plan = planCoverage(f, p);
  const CoverageFigures fig = coverageFigures(f, plan);
  std::printf(
      "L-shaped hectare: heading %.3f rad, %d swaths in %d parts, inner %.0f m^2, covered %.2f %% of the "
      "inner field (%.2f %% of the workable field), overlap %.2f %%, missed %.2f %%, path %.0f m, turns "
      "%.0f m, peak curvature %.3f 1/m, rate %.2f 1/m^2\n",
      plan.heading, fig.swaths, plan.parts, fig.inner_area, 100 * fig.covered_inner_share, 100 * fig.covered_share,
      100 * fig.overlap_share, 100 * fig.missed_share, fig.path_length, fig.turn_length, plan.peak_curvature,
      plan.peak_curvature_rate);
  EXPECT_NEAR(fig.field_area, 10000.0, 1e-6);
  EXPECT_GE(fig.covered_inner_share, 0.99);
  EXPECT_LE(fig.overlap_share, 0.02);
  EXPECT_LE(fig.missed_share, 0.02);
  EXPECT_EQ(plan.straight_joins, 0);
  // Every curve within the bounds: as planned, and as the route's points show it (2 % for the chords).
  EXPECT_LE(plan.peak_curvature, 1.0 / p.min_turn_radius + 1e-9);
  EXPECT_LE(plan.peak_curvature_rate, p.max_curvature_rate + 1e-9);
  EXPECT_LE(peakPointCurvature(plan.route.points), 1.02 / p.min_turn_radius);
  // The route is connected: one polyline, a tool flag per segment, swaths sown tool down.
  ASSERT_EQ(plan.route.tool_down.size() + 1, plan.route.points.size());
  EXPECT_EQ(plan.headland_rings.size(), 2u * 3u);  // two passes round the boundary, the pond and the tree
  // Auto heading: along the long edges (the fewest swaths).
  EXPECT_NEAR(std::fmod(plan.heading, M_PI / 2.0), 0.0, 1e-9);
}

// A void reaching across the inner field splits it in two: both sides swept, joined through the headland.
TEST(CoveragePlanner, ASplittingVoidIsCoveredOnBothSides) {
  FieldBoundary f;
  f.outer = rectangle(0, 0, 60, 40);
  f.voids = {rectangle(28, 2.8, 32, 37.2)};
  CoverageParams p = fieldYamlParams();
  p.heading = "0";
  const CoveragePlan plan = planCoverage(f, p);
  EXPECT_EQ(plan.parts, 2);
  EXPECT_EQ(plan.inner_field.size(), 2u);
  int left = 0, right = 0;
  for (const Swath& s : plan.swaths) (std::max(s.a.x(), s.b.x()) < 30.0 ? left : right)++;
  EXPECT_EQ(left, 36);
  EXPECT_EQ(right, 36);
  const CoverageFigures fig = coverageFigures(f, plan);
  EXPECT_GE(fig.covered_inner_share, 0.99);
  EXPECT_EQ(plan.straight_joins, 0);
  EXPECT_LE(peakPointCurvature(plan.route.points), 1.02 / p.min_turn_radius);
}

TEST(CoveragePlanner, AutoHeadingFollowsTheLongEdges) {
  FieldBoundary f;
  f.outer = rotated(rectangle(0, 0, 100, 20), 0.4);
  const CoveragePlan plan = planCoverage(f, fieldYamlParams());
  EXPECT_NEAR(plan.heading, 0.4, 1e-9);
  EXPECT_EQ(plan.swaths.size(), 16u);
}

// Narrow swaths (working width below 2 min_turn_radius): the skip pattern, whose turns are two widths wide.
TEST(CoveragePlanner, NarrowSwathsAreSkipped) {
  FieldBoundary f;
  f.outer = rectangle(0, 0, 40, 12);
  CoverageParams p = fieldYamlParams();
  p.row_spacing = 0.5;
  p.heading = "0";
  p.headland_passes = 4;
  const CoveragePlan plan = planCoverage(f, p);
  EXPECT_EQ(plan.pattern, RoutePattern::kSkip);
  ASSERT_GE(plan.swaths.size(), 3u);
  EXPECT_EQ(std::abs(plan.swaths[1].line - plan.swaths[0].line), 2);
  EXPECT_LE(peakPointCurvature(plan.route.points), 1.02 / p.min_turn_radius);
  EXPECT_LE(plan.peak_curvature_rate, p.max_curvature_rate + 1e-9);
}

TEST(CoveragePlanner, EachEdgeGivesItsLine) {
  const CoverageParams p = fieldYamlParams();
  FieldBoundary bowtie;
  bowtie.outer = {{0, 0}, {50, 50}, {50, 0}, {0, 50}};
  std::string e = errorOf(bowtie, p);
  EXPECT_EQ(e.rfind("field boundary is not a simple polygon: ", 0), 0u) << e;
  EXPECT_NE(e.find("intersects itself"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;

  FieldBoundary bad_void = lShapedHectare();
  bad_void.voids.push_back({{10, 10}, {15, 15}, {15, 10}, {10, 15}});
  e = errorOf(bad_void, p);
  EXPECT_EQ(e.rfind("void 1 is not a simple polygon: ", 0), 0u) << e;

  FieldBoundary outside = lShapedHectare();
  outside.voids.push_back(rectangle(80, 60, 90, 70));  // in the L's notch
  EXPECT_EQ(errorOf(outside, p), "void 1 lies outside the field boundary");
  FieldBoundary circle_outside = lShapedHectare();
  circle_outside.circles.push_back(Obstacle{200.0, 0.0, 1.0});
  EXPECT_EQ(errorOf(circle_outside, p), "circular void 1 lies outside the field boundary");

  FieldBoundary narrow;
  narrow.outer = rectangle(0, 0, 50, 4.5);  // two passes of 1 m each side leave 0.5 m
  e = errorOf(narrow, p);
  EXPECT_NE(e.find("narrower than one swath"), std::string::npos) << e;

  for (const double spacing : {0.0, -1.0}) {
    CoverageParams zero = p;
    zero.row_spacing = spacing;
    e = errorOf(lShapedHectare(), zero);
    EXPECT_EQ(e.rfind("coverage/row_spacing = ", 0), 0u) << e;
    EXPECT_NE(e.find("> 0"), std::string::npos) << e;
  }
  CoverageParams heading = p;
  heading.heading = "north";
  EXPECT_NE(errorOf(lShapedHectare(), heading).find("coverage/heading"), std::string::npos);
}

// The route is a CoveragePath the path follower takes as it is (path_plan.h).
TEST(CoveragePlanner, ThePathFollowerTakesTheRoute) {
  FieldBoundary f;
  f.outer = rectangle(0, 0, 40, 20);
  f.circles = {Obstacle{20.0, 10.0, 2.0}};
  const CoverageParams p = fieldYamlParams();
  const CoveragePlan plan = planCoverage(f, p);
  FieldParams field;
  EXPECT_EQ(coverageFollowerParams(field, p).max_curvature, 2.5 / p.min_turn_radius);
  EXPECT_EQ(coverageFollowerParams(field, p).v_max, field.row_speed);
  // From behind the field: the follower reaches the route's end, the tool down on the way and up on the approach.
  PathReference follower = coverageReference(plan, Pose2D{-5.0, -3.0, 0.0}, field, p);
  const double end = follower.planStart() + follower.plan().duration();
  EXPECT_GT(end, plan.path_length / field.row_speed);
  EXPECT_FALSE(follower.plan().at(0.0).tool_down);
  const Reference last = follower.plan().at(end + 1.0);
  EXPECT_LT((Eigen::Vector2d(last.pose.x, last.pose.y) - plan.route.points.back()).norm(), 1e-6);
}

// From the robot's start pose (behind the field, facing away): a tool-up approach within the turn bounds, then
// the route unchanged.
TEST(CoveragePlanner, TheRouteStartsFromTheRobotsPose) {
  FieldBoundary f;
  f.outer = rectangle(0, 0, 40, 20);
  const CoverageParams p = fieldYamlParams();
  const CoveragePlan plan = planCoverage(f, p);
  const CoveragePath path = coverageFrom(plan, Pose2D{-5.0, -3.0, M_PI}, p);
  ASSERT_EQ(path.tool_down.size() + 1, path.points.size());
  EXPECT_LT((path.points.front() - Eigen::Vector2d(-5.0, -3.0)).norm(), 1e-12);
  const std::size_t lead = path.points.size() - plan.route.points.size();
  ASSERT_GT(lead, 2u);
  for (std::size_t i = 0; i < lead; ++i) EXPECT_FALSE(path.tool_down[i]) << i;
  for (std::size_t i = 0; i < plan.route.points.size(); ++i) EXPECT_EQ(path.points[lead + i], plan.route.points[i]);
  EXPECT_LE(peakPointCurvature(std::vector<Eigen::Vector2d>(path.points.begin(), path.points.begin() + lead + 2)),
            1.02 / p.min_turn_radius);
  EXPECT_THROW(coverageFrom(plan, Pose2D{NAN, 0.0, 0.0}, p), std::invalid_argument);
}

TEST(CoverageMetrics, AreaSownFollowsTheSeedRuns) {
  // Two rows of 11 seeds 0.1 m apart (1 m each) and a lone seed: 2 x 1 m x 0.5 m.
  std::vector<Seed> seeds;
  double t = 0.0;
  for (int row = 0; row < 2; ++row)
    for (int i = 0; i <= 10; ++i) {
      Seed s;
      s.t = t += 0.1;
      s.row = row;
      s.truth = {0.1 * i, 2.0 * row};
      seeds.push_back(s);
    }
  Seed lone;
  lone.t = t + 1.0;
  lone.row = 1;
  lone.truth = {5.0, 2.0};
  seeds.push_back(lone);
  EXPECT_NEAR(areaSown(seeds, 0.5, 0.1), 1.0, 1e-9);
  EXPECT_THROW(areaSown(seeds, 0.0, 0.1), std::invalid_argument);
}

// The tool point trails the axle by run_out: each swath is driven on that far past its end, the tool lowered that far
// past its start (the axle's stretch with the tool point over the row); what the tool sweeps, and so the figures, stay.
TEST(CoveragePlanner, RunOutDrivesEachSwathOnPastItsEnd) {
  FieldBoundary f;
  f.outer = rectangle(0, 0, 40, 20);
  f.circles = {Obstacle{20.0, 10.0, 2.0}};
  CoverageParams p = fieldYamlParams();
  const CoveragePlan without = planCoverage(f, p);
  p.run_out = 0.45;
  const CoveragePlan with = planCoverage(f, p);
  ASSERT_EQ(with.swaths.size(), without.swaths.size());
  const CoveragePath& route = with.route;
  for (const Swath& s : with.swaths) {
    const Eigen::Vector2d on = p.run_out * (s.b - s.a).normalized();
    // The segment from a + run_out to b + run_out is in the route, tool down, after a tool-up one from a.
    bool found = false;
    for (std::size_t i = 1; i + 1 < route.points.size(); ++i) {
      if ((route.points[i] - (s.a + on)).norm() < 1e-9 && (route.points[i + 1] - (s.b + on)).norm() < 1e-9) {
        found = true;
        EXPECT_TRUE(route.tool_down[i]);
        EXPECT_FALSE(route.tool_down[i - 1]);
        EXPECT_LT((route.points[i - 1] - s.a).norm(), 1e-9);
      }
    }
    EXPECT_TRUE(found) << "swath from (" << s.a.transpose() << ")";
  }
  const CoverageFigures a = coverageFigures(f, without), b = coverageFigures(f, with);
  EXPECT_NEAR(b.covered_share, a.covered_share, 1e-6);  // the headland loops start elsewhere: Boost's rounding
  EXPECT_NEAR(b.overlap_share, a.overlap_share, 1e-6);
  EXPECT_GT(with.path_length, without.path_length);
  EXPECT_EQ(with.straight_joins, 0);
  EXPECT_LE(with.peak_curvature, 1.0 / p.min_turn_radius + 1e-9);
  CoverageParams bad = p;
  bad.run_out = -0.1;
  EXPECT_THROW(planCoverage(f, bad), std::invalid_argument);
}

// The headland loops' straight sides are rows of the plan, after the swaths' and in the order they are driven: each on
// a tool-down segment of the route along a headland ring, from the side's start to run_out short of its end (where the
// trailing tool point is when the axle turns into the corner). The corners' chords are tool up, and no row; so are the
// rings round the tree (a 3 m circle: 0.6 m chords).
TEST(CoveragePlanner, TheHeadlandSidesAreRowsAndTheirCornersAreNot) {
  const FieldBoundary f = lShapedHectare();
  CoverageParams p = fieldYamlParams();
  p.run_out = 0.45;
  const CoveragePlan plan = planCoverage(f, p);
  const std::vector<RowSegment> rows = plan.rows();
  ASSERT_EQ(rows.size(), plan.swathRows() + plan.headland_rows.size());
  // Sides: the L's six and the pond's four on each of the two passes; not one round the tree.
  EXPECT_EQ(plan.headland_rows.size(), 2u * (6u + 4u));
  const CoveragePath& route = plan.route;
  std::size_t next = 0;  // the headland rows are met along the route in their order
  double side_length = 0.0, row_length = 0.0, up_on_loops = 0.0;
  std::size_t first_loop = 0;  // the route's first segment on a headland ring: after the last swath
  for (std::size_t i = 0; i + 1 < route.points.size(); ++i)
    if ((route.points[i + 1] - plan.swaths.back().b).norm() < p.run_out + 1e-9) first_loop = i + 1;
  for (std::size_t i = first_loop; i + 1 < route.points.size(); ++i) {
    const Eigen::Vector2d &a = route.points[i], &b = route.points[i + 1];
    if (!route.tool_down[i]) continue;
    ASSERT_TRUE(headlandSide(a, b, p)) << "tool down off a straight side at route point " << i;
    ASSERT_LT(next, plan.headland_rows.size());
    const RowSegment& r = plan.headland_rows[next++];
    const Eigen::Vector2d u = (b - a).normalized();
    EXPECT_LT((r.a - a).norm(), 1e-9);
    EXPECT_LT((r.b - (b - p.run_out * u)).norm(), 1e-9);
    side_length += (b - a).norm();
    row_length += (r.b - r.a).norm();
    // On a headland ring's line: both ends are ring vertices.
    bool on_ring = false;
    for (const Ring& ring : plan.headland_rings)
      for (std::size_t v = 0; v < ring.size(); ++v)
        on_ring = on_ring || ((ring[v] - a).norm() < 1e-9 && (ring[(v + 1) % ring.size()] - b).norm() < 1e-9);
    EXPECT_TRUE(on_ring) << "a tool-down headland segment off the rings at route point " << i;
  }
  EXPECT_EQ(next, plan.headland_rows.size());
  // Every ring's sides were driven tool down (one row each), its other edges (corners, curves) tool up.
  std::size_t sides = 0;
  for (const Ring& ring : plan.headland_rings)
    for (std::size_t v = 0; v < ring.size(); ++v) {
      const bool side = headlandSide(ring[v], ring[(v + 1) % ring.size()], p);
      sides += side ? 1 : 0;
      if (!side) up_on_loops += (ring[(v + 1) % ring.size()] - ring[v]).norm();
    }
  EXPECT_EQ(sides, plan.headland_rows.size());
  EXPECT_NEAR(side_length - row_length, p.run_out * plan.headland_rows.size(), 1e-6);
  // The L's two passes are some 2 x 470 m round (less the corners and the run-outs); the pond's 2 x 60 m or so.
  EXPECT_GT(row_length, 1000.0);
  EXPECT_GT(up_on_loops, 0.0);
  const CoverageFigures fig = coverageFigures(f, plan);
  EXPECT_GT(fig.row_area, 0.97 * fig.covered_area);
  EXPECT_LT(fig.row_area, fig.covered_area);
}
