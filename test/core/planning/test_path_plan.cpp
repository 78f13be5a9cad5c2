// The path follower's plan: simplification, rounded corners and pivots, the speed profile's limits, the
// reference's continuity and derivatives, and a path replaced while the robot moves.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sowing_robot/core/planning/path_plan.h"

namespace sowing_robot {
namespace core {
namespace {

using Points = std::vector<Eigen::Vector2d>;

/// The rostest's path: a U-turn 2 m wide, then a 90 degree corner (right).
Points cornerAndUTurn() { return {{0, 0}, {6, 0}, {6, 2}, {0, 2}, {0, 5}}; }

double distanceToPolyline(const Eigen::Vector2d& p, const Points& pts) {
  double best = 1e9;
  for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
    best = std::min(best, (p - (pts[k] + segmentParameter(p, pts[k], pts[k + 1]) * (pts[k + 1] - pts[k]))).norm());
  }
  return best;
}

TEST(SimplifyPolyline, DropsCollinearPointsAndRepeatsKeepsCorners) {
  Points dense;
  for (int i = 0; i <= 100; ++i) dense.emplace_back(0.05 * i, 0.004 * (i % 2));  // 4 mm grid jitter
  dense.emplace_back(5.0, 3.0);
  const Points s = simplifyPolyline(dense, 0.02);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_NEAR(s[1].x(), 5.0, 1e-12);
  EXPECT_EQ(simplifyPolyline({{0, 0}, {0, 0.0005}, {1, 0}}, 0.0).size(), 2u);  // a repeat within 1 mm
  EXPECT_EQ(simplifyPolyline(dense, 0.0).size(), dense.size());
}

TEST(PathPlan, StraightFromRestRampsToVMaxAndStopsAtTheGoal) {
  PathParams p;
  const PathPlan plan({{0, 0}, {10, 0}}, PathStart{}, p);
  EXPECT_EQ(plan.pivots(), 0);
  EXPECT_EQ(plan.fillets(), 0);
  EXPECT_NEAR(plan.length(), 10.0, 1e-12);
  // Half-cosine ramps: pi v / (2 a) each, over pi v^2 / (4 a) metres; the rest at v_max.
  const double ramp_t = M_PI * p.v_max / (2 * p.a_max), ramp_s = M_PI * p.v_max * p.v_max / (4 * p.a_max);
  EXPECT_NEAR(plan.duration(), 2 * ramp_t + (10 - 2 * ramp_s) / p.v_max, 1e-9);
  const Reference mid = plan.at(plan.duration() / 2);
  EXPECT_NEAR(mid.v, p.v_max, 1e-12);
  EXPECT_NEAR(mid.pose.x, 5.0, 1e-9);
  EXPECT_FALSE(mid.stop);
  const Reference end = plan.at(plan.duration() + 1);
  EXPECT_TRUE(end.stop);
  EXPECT_NEAR(end.pose.x, 10.0, 1e-12);
  EXPECT_EQ(end.v, 0.0);
}

/// Samples the whole plan at 1 ms and checks continuity, the derivatives the controllers are given, and
/// the limits.
void checkPlan(const PathPlan& plan, const PathParams& p, double dt = 1e-3) {
  Reference prev = plan.at(0.0);
  double max_lat = 0, max_vdot = 0, max_v = 0, max_w = 0;
  for (double t = dt; t <= plan.duration() + 0.5; t += dt) {
    const Reference r = plan.at(t);
    if (r.stop) break;
    // position follows the heading and speed; heading follows omega (trapezoid over one step)
    const double vm = 0.5 * (r.v + prev.v), thm = prev.pose.theta + 0.5 * wrapAngle(r.pose.theta - prev.pose.theta);
    EXPECT_NEAR(r.pose.x - prev.pose.x, vm * std::cos(thm) * dt, 2e-6) << "t " << t;
    EXPECT_NEAR(r.pose.y - prev.pose.y, vm * std::sin(thm) * dt, 2e-6) << "t " << t;
    EXPECT_NEAR(wrapAngle(r.pose.theta - prev.pose.theta), 0.5 * (r.omega + prev.omega) * dt, 2e-6) << "t " << t;
    EXPECT_NEAR(r.v - prev.v, 0.5 * (r.v_dot + prev.v_dot) * dt, 2e-6) << "t " << t;
    EXPECT_NEAR(r.omega - prev.omega, 0.5 * (r.omega_dot + prev.omega_dot) * dt, 1e-4) << "t " << t;
    max_lat = std::max(max_lat, std::fabs(r.v * r.omega));
    max_vdot = std::max(max_vdot, std::fabs(r.v_dot));
    max_v = std::max(max_v, r.v);
    max_w = std::max(max_w, std::fabs(r.v) < 1e-12 ? std::fabs(r.omega) : 0.0);
    EXPECT_GE(r.v, -1e-12);
    prev = r;
  }
  EXPECT_LE(max_lat, p.lateral_accel * (1 + 1e-9));
  EXPECT_LE(max_vdot, p.a_max * (1 + 1e-9));
  EXPECT_LE(max_v, p.v_max * (1 + 1e-12));
  EXPECT_LE(max_w, p.turn_rate * (1 + 1e-9));
}

TEST(PathPlan, CornerAndUTurnAreRoundedContinuousAndWithinTheLimits) {
  PathParams p;
  const Points pts = cornerAndUTurn();
  const PathPlan plan(pts, PathStart{}, p);
  EXPECT_EQ(plan.fillets(), 3);
  EXPECT_EQ(plan.pivots(), 0);
  checkPlan(plan, p);
  // Every reference lies within the largest corner cut of the given polyline, and it ends at the goal.
  EXPECT_GT(plan.maxCornerCut(), 0.01);
  EXPECT_LT(plan.maxCornerCut(), 0.3);
  for (double t = 0; t < plan.duration(); t += 0.01) {
    const Reference r = plan.at(t);
    EXPECT_LE(distanceToPolyline({r.pose.x, r.pose.y}, pts), plan.maxCornerCut() + 1e-6) << "t " << t;
  }
  const Reference end = plan.at(plan.duration());
  EXPECT_NEAR(end.pose.x, 0.0, 1e-12);
  EXPECT_NEAR(end.pose.y, 5.0, 1e-12);
  EXPECT_NEAR(end.pose.theta, M_PI / 2, 1e-12);
}

TEST(PathPlan, TightOrSharpCornersAreTurnedInPlace) {
  PathParams p;
  // 0.3 m between two 90 degree corners: no rounding within max_curvature fits; then a reversal.
  const PathPlan plan({{0, 0}, {3, 0}, {3, 0.3}, {1, 0.3}, {3, 0.31}}, PathStart{}, p);
  EXPECT_EQ(plan.pivots(), 3);
  checkPlan(plan, p);
  // While it turns in place the reference is at rest on the corner, with the tool up.
  bool seen = false;
  for (double t = 0; t < plan.duration(); t += 0.01) {
    const Reference r = plan.at(t);
    if (std::fabs(r.omega) > 0.1) {
      seen = true;
      EXPECT_EQ(r.v, 0.0);
      EXPECT_FALSE(r.tool_down);
    }
  }
  EXPECT_TRUE(seen);
}

TEST(PathPlan, StartHeadingOffThePathTurnsFirst) {
  PathParams p;
  p.tool_down = true;
  const PathPlan plan({{0, 0}, {4, 0}}, PathStart{Pose2D{0, 0, M_PI / 2}, 0.0}, p);
  EXPECT_EQ(plan.pivots(), 1);
  EXPECT_NEAR(plan.at(0.0).pose.theta, M_PI / 2, 1e-12);
  EXPECT_FALSE(plan.at(0.1).tool_down);
  EXPECT_TRUE(plan.at(plan.duration() - 1.0).tool_down);
  EXPECT_NEAR(plan.at(plan.duration() - 1.0).pose.theta, 0.0, 1e-12);
}

TEST(PathPlan, ProjectionAndTimingAreConsistent) {
  PathParams p;
  const PathPlan plan(cornerAndUTurn(), PathStart{}, p);
  const PathPlan::Projection left = plan.project({3.0, 0.2}, 0.0, plan.length());
  EXPECT_NEAR(left.s, 3.0, 1e-9);
  EXPECT_NEAR(left.cross_track, 0.2, 1e-9);  // left of travel: positive
  EXPECT_NEAR(plan.project({3.0, -0.1}, 0.0, 5.0).cross_track, -0.1, 1e-9);
  for (double t : {1.0, 5.0, 9.0, 15.0}) EXPECT_NEAR(plan.timeAt(plan.arcLengthAt(t)), t, 1e-6) << t;
  // A point on a rounded corner projects onto itself.
  const Reference r = plan.at(plan.timeAt(6.1));
  const PathPlan::Projection on = plan.project({r.pose.x, r.pose.y}, 0.0, plan.length());
  EXPECT_NEAR(on.s, plan.arcLengthAt(plan.timeAt(6.1)), 2e-3);
  EXPECT_NEAR(on.cross_track, 0.0, 1e-4);
}

TEST(PathPlan, RejectsBadInput) {
  PathParams p;
  EXPECT_THROW(PathPlan({}, PathStart{}, p), std::invalid_argument);
  EXPECT_THROW(PathPlan({{0, 0}, {NAN, 1}}, PathStart{}, p), std::invalid_argument);
  p.v_max = -1;
  EXPECT_THROW(PathPlan({{0, 0}, {1, 1}}, PathStart{}, p), std::invalid_argument);
}

TEST(PathPlan, ToolFlagsHoldPerSegmentAndKeepTheirPointsThroughSimplification) {
  PathParams p;
  // Down, up, down along a straight line: without the flags the middle points would be simplified away.
  const Points pts{{0, 0}, {4, 0}, {6, 0}, {10, 0}};
  const PathPlan plan(pts, PathStart{}, p, {true, false, true});
  EXPECT_EQ(plan.vertices().size(), 4u);
  for (double tau = 0.0; tau < plan.duration(); tau += 0.01) {
    const Reference r = plan.at(tau);
    if (r.pose.x < 3.99) EXPECT_TRUE(r.tool_down) << r.pose.x;
    if (r.pose.x > 4.01 && r.pose.x < 5.99) EXPECT_FALSE(r.tool_down) << r.pose.x;
    if (r.pose.x > 6.01) EXPECT_TRUE(r.tool_down) << r.pose.x;
  }
  EXPECT_FALSE(plan.at(plan.duration()).tool_down);  // the end hold
  // A rounded corner keeps the tool down only between two tool-down segments.
  const PathPlan corner({{0, 0}, {5, 0}, {5, 5}}, PathStart{}, p, {true, false});
  const Reference mid = corner.at(corner.timeAt(5.0));
  EXPECT_FALSE(mid.tool_down);
  EXPECT_EQ(corner.fillets(), 1);
  // Flags that do not fit, and the lead from a moving start (a transit: up).
  EXPECT_THROW(PathPlan(pts, PathStart{}, p, {true}), std::invalid_argument);
  const PathPlan led({{2, 0}, {10, 0}}, PathStart{Pose2D{0, 0, 0}, 0.8}, p, {true});
  EXPECT_FALSE(led.at(0.05).tool_down);
  EXPECT_TRUE(led.at(led.duration() - 0.5).tool_down);
  // Without flags: path/tool_down everywhere, the lead too (as before the flags).
  p.tool_down = true;
  const PathPlan plain({{2, 0}, {10, 0}}, PathStart{Pose2D{0, 0, 0}, 0.8}, p);
  EXPECT_TRUE(plain.at(0.05).tool_down);
}

TEST(PathReference, HoldsTheStartUntilAPathComesThenReplacesItContinuously) {
  PathParams p;
  PathReference ref(p, Pose2D{0, 0, 0});
  EXPECT_TRUE(ref.next(0.0).stop);
  ref.setPath({{0, 0}, {20, 0}});
  double t = 0;
  for (; t < 8.0; t += 0.001) ref.next(t);
  const Reference before = ref.next(t);
  ASSERT_GT(before.v, 0.5);
  // A replacement 0.5 m to the left that starts behind the robot: joined from the robot's progress, not its start.
  ref.setPath({{0, 0.5}, {30, 0.5}});
  EXPECT_THROW(ref.setPath({{0, 0}, {INFINITY, 0}}), std::invalid_argument);  // the path in force is kept
  Reference prev = before;
  for (double u = t + 0.001; u < t + 60; u += 0.001) {
    const Reference r = ref.next(u);
    EXPECT_GE(r.pose.x, prev.pose.x - 1e-12) << "went back at " << u;
    EXPECT_NEAR(r.v, prev.v, 1e-3) << u;
    EXPECT_NEAR(std::hypot(r.pose.x - prev.pose.x, r.pose.y - prev.pose.y), 0.001 * 0.5 * (r.v + prev.v), 1e-5) << u;
    prev = r;
  }
  EXPECT_TRUE(prev.stop);
  EXPECT_NEAR(prev.pose.x, 30.0, 1e-9);
  EXPECT_NEAR(prev.pose.y, 0.5, 1e-9);
  // reset() and clone() go back to the path given at construction (here none: the start hold).
  EXPECT_TRUE(ref.clone()->next(1.0).stop);
}

}  // namespace
}  // namespace core
}  // namespace sowing_robot
