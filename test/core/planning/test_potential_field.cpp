#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "sowing_robot/core/planning/potential_field.h"

using sowing_robot::core::AvoidSide;
using sowing_robot::core::Obstacle;
using sowing_robot::core::PotentialField;
using sowing_robot::core::PotentialFieldParams;
using sowing_robot::core::Reference;
using sowing_robot::core::RowLine;
using sowing_robot::core::TargetState;
using sowing_robot::core::wrapAngle;

namespace {

/// Sample t = k ms for k = 0..n and call f(t, reference).
template <typename F>
void sampleEveryMs(PotentialField& pf, int n, F f) {
  for (int k = 0; k <= n; ++k) {
    const double t = k * 1e-3;
    f(t, pf.next(t));
  }
}

bool sameReference(const Reference& a, const Reference& b) {
  return a.pose.x == b.pose.x && a.pose.y == b.pose.y && a.pose.theta == b.pose.theta && a.v == b.v &&
         a.omega == b.omega && a.v_dot == b.v_dot && a.omega_dot == b.omega_dot && a.tool_down == b.tool_down;
}

}  // namespace

TEST(PotentialFieldParams, ValidateNamesTheBadParameter) {
  EXPECT_EQ(PotentialFieldParams{}.validate(), "");
  auto bad = [](auto mutate, const std::string& name) {
    PotentialFieldParams p;
    mutate(p);
    const std::string e = p.validate();
    EXPECT_NE(e.find(name), std::string::npos) << e;
  };
  bad([](PotentialFieldParams& p) { p.alpha = 0.0; }, "alpha");
  bad([](PotentialFieldParams& p) { p.beta = -1.0; }, "beta");
  bad([](PotentialFieldParams& p) { p.influence_distance = 0.0; }, "influence_distance");
  bad([](PotentialFieldParams& p) { p.gain = -0.1; }, "gain");
  bad([](PotentialFieldParams& p) { p.tangential_ratio = std::nan(""); }, "tangential_ratio");
  bad([](PotentialFieldParams& p) { p.step = 2e-3; }, "step");
  bad([](PotentialFieldParams& p) { p.core_fraction = 1.0; }, "core_fraction");
  bad([](PotentialFieldParams& p) { p.side_band = -0.01; }, "side_band");
  bad([](PotentialFieldParams& p) { p.heading_hold_speed = -1.0; }, "heading_hold_speed");
  EXPECT_NE((Obstacle{0.0, 0.0, 0.0}.validate().find("radius")), std::string::npos);
  EXPECT_NE((RowLine{0.0, 0.0, 0.0, 0.0}.validate().find("speed")), std::string::npos);

  PotentialFieldParams p;
  p.alpha = -1.0;
  EXPECT_THROW(PotentialField(p, RowLine{}), std::invalid_argument);
  EXPECT_THROW(PotentialField({}, RowLine{}, {{1.0, 2.0, -0.3}}), std::invalid_argument);
  PotentialField ok({}, RowLine{});
  EXPECT_THROW(ok.setObstacles({{1.0, 2.0, 0.0}}), std::invalid_argument);
}

TEST(PotentialField, GradientMatchesCentralDifference) {
  // Two obstacles whose influence zones overlap, so sums are checked too.
  PotentialField pf({}, RowLine{}, {{0.0, 0.0, 0.3}, {1.0, 0.2, 0.5}});
  const double d = pf.params().influence_distance;
  int checked = 0;
  for (const double rho : {0.02, 0.04, 0.07, 0.12, 0.2, 0.3, 0.4, 0.47}) {
    for (const double ang : {0.1, 1.3, 2.9, 4.0, 5.5}) {
      const Eigen::Vector2d p = (0.3 + rho) * Eigen::Vector2d(std::cos(ang), std::sin(ang));
      ASSERT_LT(pf.minObstacleClearance(p), d);
      const Eigen::Vector2d g = pf.repulsiveGradient(p);
      const double h = 1e-6;
      Eigen::Vector2d fd;
      for (int i = 0; i < 2; ++i) {
        Eigen::Vector2d dp = Eigen::Vector2d::Zero();
        dp[i] = h;
        fd[i] = (pf.repulsivePotential(p + dp) - pf.repulsivePotential(p - dp)) / (2.0 * h);
      }
      ASSERT_GT(g.norm(), 0.0);
      EXPECT_LE((g - fd).norm(), 1e-5 * g.norm())
          << "rho " << rho << " angle " << ang << " g " << g.transpose() << " fd " << fd.transpose();
      ++checked;
    }
  }
  EXPECT_EQ(checked, 40);
}

TEST(PotentialField, ClearanceIsMeasuredFromTheSurface) {
  PotentialField pf({}, RowLine{}, {{2.0, 1.0, 0.3}, {5.0, 1.0, 1.0}});
  EXPECT_NEAR(pf.minObstacleClearance({2.0, 1.5}), 0.2, 1e-15);
  EXPECT_NEAR(pf.minObstacleClearance({5.0, 2.25}), 0.25, 1e-15);
  EXPECT_EQ(PotentialField({}, RowLine{}).minObstacleClearance({0.0, 0.0}), std::numeric_limits<double>::infinity());
  // V_a = (1/2 (d/rho - 1))^2 with rho from the surface (thesis eq 4.37 with the corrected distance).
  const double rho = 0.2, d = 0.5;
  EXPECT_NEAR(pf.repulsivePotential({2.0, 1.0 + 0.3 + rho}), std::pow(0.5 * (d / rho - 1.0), 2), 1e-14);
}

TEST(PotentialField, NoRepulsionOutsideTheInfluenceDistance) {
  PotentialField pf({}, RowLine{}, {{0.0, 0.0, 0.3}});
  TargetState tgt;
  tgt.p = {-3.0, 0.0};
  tgt.v = {1.0, 0.0};
  for (const double rho : {0.5 + 1e-9, 0.6, 1.0, 10.0}) {
    for (const double ang : {0.0, 1.0, 2.0, 3.0, 4.5}) {
      const Eigen::Vector2d p = (0.3 + rho) * Eigen::Vector2d(std::cos(ang), std::sin(ang));
      EXPECT_EQ(pf.repulsivePotential(p), 0.0);
      EXPECT_EQ(pf.repulsiveGradient(p).norm(), 0.0);
      EXPECT_EQ(pf.repulsiveAcceleration(p, tgt).norm(), 0.0);
    }
  }
  // At the boundary itself (up to rounding of the test point) nothing is left.
  const Eigen::Vector2d edge(0.3 + 0.5, 0.0);
  EXPECT_LE(pf.repulsivePotential(edge), 1e-30);
  EXPECT_LE(pf.repulsiveGradient(edge).norm(), 1e-14);
  // Just inside, potential and gradient fade out continuously (V ~ delta^2, |grad V| ~ delta).
  const double delta = 1e-4;
  const Eigen::Vector2d p(0.3 + 0.5 - delta, 0.0);
  EXPECT_GT(pf.repulsivePotential(p), 0.0);
  EXPECT_LT(pf.repulsivePotential(p), 4.0 * delta * delta);
  EXPECT_LT(pf.repulsiveGradient(p).norm(), 4.0 * delta);
}

TEST(PotentialField, WithoutObstaclesTheReferenceIsTheLine) {
  const RowLine row{1.0, -2.0, 0.7, 1.3};
  // A far obstacle must not change anything either.
  for (const bool far_obstacle : {false, true}) {
    std::vector<Obstacle> obs;
    if (far_obstacle) obs.push_back({50.0, 50.0, 0.3});
    PotentialField pf({}, row, obs);
    const Eigen::Vector2d u(std::cos(row.heading), std::sin(row.heading));
    double worst = 0.0;
    auto check = [&](double t, const Reference& r) {
      const Eigen::Vector2d line = Eigen::Vector2d(row.x0, row.y0) + row.speed * t * u;
      worst = std::max(worst, std::hypot(r.pose.x - line.x(), r.pose.y - line.y()));
      ASSERT_NEAR(r.pose.theta, row.heading, 1e-12);
      ASSERT_NEAR(r.v, row.speed, 1e-12);
      ASSERT_EQ(r.omega, 0.0);
      ASSERT_EQ(r.v_dot, 0.0);
      ASSERT_EQ(r.omega_dot, 0.0);
      ASSERT_TRUE(r.tool_down);
    };
    sampleEveryMs(pf, 30000, check);
    for (double t = 30.0; t < 120.0; t += 0.7371) check(t, pf.next(t));  // irregular, larger jumps
    EXPECT_LE(worst, 1e-12);
  }
}

namespace {
struct PassResult {
  double min_clearance = std::numeric_limits<double>::infinity();
  double max_left = -1e9, min_left = 1e9;  ///< lateral offset from the line (left positive) near the obstacle
  double t_pass = -1.0;                    ///< first time x >= obstacle + 2 m
  double last_off_line_x = 0.0;            ///< last x where the reference was >= 1 cm from the target
  bool x_monotone = true;
};

/// Row along +x at y = 3 from x = 0; one obstacle at (10, 3 + offset).
PassResult runPast(const PotentialFieldParams& params, double offset, double duration) {
  const Obstacle ob{10.0, 3.0 + offset, 0.3};
  PotentialField pf(params, RowLine{0.0, 3.0, 0.0, 1.0}, {ob});
  PassResult r;
  double last_x = -1e9;
  sampleEveryMs(pf, static_cast<int>(duration * 1e3), [&](double t, const Reference& ref) {
    const Eigen::Vector2d p(ref.pose.x, ref.pose.y);
    r.min_clearance = std::min(r.min_clearance, pf.minObstacleClearance(p));
    if (std::fabs(p.x() - ob.x) < 1.0) {
      r.max_left = std::max(r.max_left, p.y() - 3.0);
      r.min_left = std::min(r.min_left, p.y() - 3.0);
    }
    if (r.t_pass < 0.0 && p.x() >= ob.x + 2.0) r.t_pass = t;
    if ((p - Eigen::Vector2d(t, 3.0)).norm() >= 0.01) r.last_off_line_x = p.x();
    if (p.x() < last_x) r.x_monotone = false;
    last_x = p.x();
  });
  return r;
}
}  // namespace

TEST(PotentialField, GoesAroundAnObstacleOnTheLineAndRejoins) {
  const PassResult r = runPast({}, 0.0, 45.0);
  // Never inside the obstacle (checked every 1 ms), and with a useful margin.
  EXPECT_GT(r.min_clearance, 0.1);
  EXPECT_LT(r.min_clearance, 0.5);  // it did come into the influence zone
  // Went around on the left (the default for an obstacle on the line).
  EXPECT_GT(r.max_left, 0.3 + 0.1);
  EXPECT_GE(r.min_left, -1e-9);
  // Back within 1 cm of the target (hence of the line) within 30 m after the obstacle.
  EXPECT_LT(r.last_off_line_x, 10.0 + 30.0);
  EXPECT_GT(r.last_off_line_x, 10.0);
}

TEST(PotentialField, SymmetricCaseDoesNotStall) {
  const PassResult r = runPast({}, 0.0, 20.0);
  EXPECT_TRUE(r.x_monotone);
  ASSERT_GT(r.t_pass, 0.0);
  EXPECT_LT(r.t_pass, 10.0 + 2.0 + 1.0);  // the target passes x = 12 at t = 12
  // Without the tangential term the same case stalls in front of the obstacle: the term is what fixes it.
  PotentialFieldParams radial_only;
  radial_only.tangential_ratio = 0.0;
  const PassResult s = runPast(radial_only, 0.0, 20.0);
  EXPECT_LT(s.t_pass, 0.0);
  EXPECT_GT(s.min_clearance, 0.0);
  EXPECT_NEAR(s.max_left, 0.0, 1e-12);
}

TEST(PotentialField, AvoidSideIsDeterministicAndConfigurable) {
  // On the line the tie-break side is used: right when asked.
  PotentialFieldParams right;
  right.avoid_side = AvoidSide::kRight;
  const PassResult r = runPast(right, 0.0, 20.0);
  EXPECT_LT(r.min_left, -0.4);
  EXPECT_LE(r.max_left, 1e-9);
  EXPECT_GT(r.min_clearance, 0.1);

  // nearest_side: an obstacle 0.2 m left of the line is passed on the right, one 0.2 m right on the left,
  // without ever crossing the line.
  const PassResult a = runPast({}, 0.2, 20.0), b = runPast({}, -0.2, 20.0);
  EXPECT_LT(a.min_left, -0.1);
  EXPECT_LE(a.max_left, 1e-9);
  EXPECT_GT(b.max_left, 0.1);
  EXPECT_GE(b.min_left, -1e-9);
  EXPECT_GT(a.min_clearance, 0.1);
  // Inside the tie band (|offset| <= side_band) the tie-break side wins.
  const PassResult c = runPast({}, 0.03, 20.0);
  EXPECT_GT(c.max_left, 0.3 + 0.03);
  // Fixed side: the obstacle left of the line is passed on the left (the long way), still clear of it.
  PotentialFieldParams fixed;
  fixed.nearest_side = false;
  const PassResult f = runPast(fixed, 0.2, 25.0);
  EXPECT_GT(f.max_left, 0.2 + 0.3);
  EXPECT_GT(f.min_clearance, 0.1);
  EXPECT_GT(f.t_pass, 0.0);
}

TEST(PotentialField, CloseObstaclesShareASideInsteadOfSqueezingBetween) {
  // Two obstacles 4 cm apart (surfaces), symmetric about the line, and a staggered pair.
  for (const bool staggered : {false, true}) {
    const std::vector<Obstacle> obs{{10.0, 3.32, 0.3}, {staggered ? 10.4 : 10.0, 2.68, 0.3}};
    PotentialField pf({}, RowLine{}, obs);
    double min_clearance = 1e9, max_y = -1e9, min_y = 1e9;
    bool passed = false;
    sampleEveryMs(pf, 25000, [&](double, const Reference& ref) {
      min_clearance = std::min(min_clearance, pf.minObstacleClearance({ref.pose.x, ref.pose.y}));
      if (ref.pose.x > 9.7 && ref.pose.x < 10.7) {
        max_y = std::max(max_y, ref.pose.y);
        min_y = std::min(min_y, ref.pose.y);
      }
      passed = passed || ref.pose.x > 13.0;
    });
    // Through the 4 cm gap the clearance would be <= 2 cm: the pair is passed as one, on one side.
    EXPECT_GT(min_clearance, 0.1) << staggered;
    EXPECT_TRUE(max_y > 3.32 + 0.3 || min_y < 2.68 - 0.3) << staggered << " " << min_y << " " << max_y;
    // Symmetric pair: the tie-break side (left); staggered: the reference meets the upper one first
    // while right of its centre, so both are passed on the right.
    if (staggered) {
      EXPECT_LT(min_y, 2.68 - 0.3);
    } else {
      EXPECT_GT(max_y, 3.32 + 0.3);
    }
    EXPECT_TRUE(passed);
  }
}

TEST(PotentialField, MatlabAppendixObstaclesAreAllPassed) {
  // Appendix values (alpha 4, beta 16, d 0.5, target x = t, y = 3), obstacles at 15 (20 in the text), 50, 80.
  const std::vector<Obstacle> obs{{15.0, 3.0, 0.3}, {20.0, 3.0, 0.3}, {50.0, 3.0, 0.3}, {80.0, 3.0, 0.3}};
  PotentialField pf({}, RowLine{}, obs);
  double min_clearance = 1e9;
  Reference last;
  sampleEveryMs(pf, 110000, [&](double, const Reference& r) {
    min_clearance = std::min(min_clearance, pf.minObstacleClearance({r.pose.x, r.pose.y}));
    last = r;
  });
  EXPECT_GT(min_clearance, 0.1);
  EXPECT_NEAR(last.pose.x, 110.0, 1e-3);
  EXPECT_NEAR(last.pose.y, 3.0, 1e-3);
}

TEST(PotentialField, DerivativesAreConsistentWhileAvoiding) {
  PotentialField pf({}, RowLine{}, {{10.0, 3.0, 0.3}});
  const double d = pf.params().influence_distance, delta = 1e-5;
  int checked = 0;
  double max_omega_dot = 0.0;
  for (int k = 9000; k < 12000; k += 7) {
    const double t = (k + 0.5) * 1e-3;
    const Reference a = pf.next(t - delta), r = pf.next(t), b = pf.next(t + delta);
    const double rho = pf.minObstacleClearance({r.pose.x, r.pose.y});
    if (std::fabs(rho - d) < 1e-3) continue;  // the jerk steps where the reference enters the zone
    const double fd_omega = wrapAngle(b.pose.theta - a.pose.theta) / (2.0 * delta);
    const double fd_vdot = (b.v - a.v) / (2.0 * delta);
    const double fd_omega_dot = (b.omega - a.omega) / (2.0 * delta);
    EXPECT_NEAR(r.omega, fd_omega, 1e-5 * std::max(1.0, std::fabs(r.omega))) << "t " << t;
    EXPECT_NEAR(r.v_dot, fd_vdot, 1e-5 * std::max(1.0, std::fabs(r.v_dot))) << "t " << t;
    EXPECT_NEAR(r.omega_dot, fd_omega_dot, 1e-4 * std::max(1.0, std::fabs(r.omega_dot))) << "t " << t;
    const Eigen::Vector2d fd_p((b.pose.x - a.pose.x) / (2.0 * delta), (b.pose.y - a.pose.y) / (2.0 * delta));
    EXPECT_NEAR(fd_p.norm(), r.v, 1e-6);
    max_omega_dot = std::max(max_omega_dot, std::fabs(r.omega_dot));
    ++checked;
  }
  EXPECT_GT(checked, 400);
  EXPECT_GT(max_omega_dot, 1.0);  // the samples did cover the manoeuvre
}

TEST(PotentialField, OutputDependsOnlyOnTheTimes) {
  const std::vector<Obstacle> obs{{6.0, 3.0, 0.3}, {9.0, 2.9, 0.4}};
  PotentialField a({}, RowLine{}, obs), b({}, RowLine{}, obs);
  // Same irregular sequence (repeats, sub-step and multi-step jumps) -> bit-identical.
  std::vector<double> ts;
  double t = 0.0;
  for (int i = 0; i < 4000; ++i) {
    ts.push_back(t);
    t += (i % 5 == 0) ? 0.0 : (i % 3 == 0 ? 0.0137 : 0.00041);
  }
  for (double x : ts) ASSERT_TRUE(sameReference(a.next(x), b.next(x))) << x;
  // A 1 kHz caller and a 7 ms caller see the same reference at common times, and reset() replays.
  PotentialField fine({}, RowLine{}, obs), coarse({}, RowLine{}, obs);
  for (int k = 0; k <= 14000; ++k) {
    const Reference rf = fine.next(k * 1e-3);
    if (k % 7 == 0) {
      ASSERT_TRUE(sameReference(rf, coarse.next(k * 1e-3))) << k;
    }
  }
  const Reference before = coarse.next(14.0);
  coarse.reset();
  for (int k = 0; k <= 1400; ++k) coarse.next(k * 1e-2);
  EXPECT_TRUE(sameReference(before, coarse.next(14.0)));
}

TEST(PotentialField, CloneIsIndependentAndReproducesTheSequence) {
  PotentialField original({}, RowLine{0.0, 3.0, 0.0, 1.0}, {{5.0, 3.0, 0.3}});
  for (int k = 0; k <= 4000; ++k) original.next(k * 1e-3);  // advance into the manoeuvre
  auto copy = original.clone();                             // in its reset state
  PotentialField fresh({}, RowLine{0.0, 3.0, 0.0, 1.0}, {{5.0, 3.0, 0.3}});
  original.reset();
  for (int k = 0; k <= 9000; ++k) {
    const double t = k * 1e-3;
    const Reference c = copy->next(t);  // interleaved calls must not disturb each other
    const Reference o = original.next(t);
    ASSERT_TRUE(sameReference(c, fresh.next(t))) << t;
    ASSERT_TRUE(sameReference(c, o)) << t;
  }
  // Obstacles changed on the original after cloning do not reach the clone.
  original.setObstacles({});
  EXPECT_EQ(static_cast<PotentialField*>(copy.get())->obstacles().size(), 1u);
}

TEST(PotentialField, ObstaclesCanChangeAtRunTime) {
  PotentialField pf({}, RowLine{}, {});
  double max_dev = 0.0, min_clearance = 1e9;
  for (int k = 0; k <= 30000; ++k) {
    const double t = k * 1e-3;
    if (k == 5000) pf.setObstacles({{12.0, 3.0, 0.3}});  // appears 7 m ahead
    if (k == 20000) pf.setObstacles({});
    const Reference r = pf.next(t);
    max_dev = std::max(max_dev, std::fabs(r.pose.y - 3.0));
    if (k >= 5000 && k < 20000) min_clearance = std::min(min_clearance, pf.minObstacleClearance({r.pose.x, r.pose.y}));
  }
  EXPECT_GT(max_dev, 0.3);
  EXPECT_GT(min_clearance, 0.1);
}

TEST(PotentialField, AReferenceStartingInsideAnObstacleIsPushedOut) {
  // The target starts at the obstacle centre: the linear core keeps the force finite.
  PotentialField pf({}, RowLine{0.0, 0.0, 0.0, 1.0}, {{0.0, 0.0, 0.3}});
  Reference r;
  sampleEveryMs(pf, 3000, [&](double, const Reference& x) {
    ASSERT_TRUE(std::isfinite(x.pose.x) && std::isfinite(x.pose.y) && std::isfinite(x.omega_dot));
    r = x;
  });
  EXPECT_GT(pf.minObstacleClearance({r.pose.x, r.pose.y}), 0.0);
}

TEST(PotentialField, GainsChangeLiveAndInvalidOnesAreRefused) {
  PotentialField pf(PotentialFieldParams{}, sowing_robot::core::RowLine{}, {});
  pf.setGains(6.0, 5.0, 2.0, 0.5);
  EXPECT_EQ(pf.params().alpha, 6.0);
  EXPECT_EQ(pf.params().beta, 5.0);
  EXPECT_EQ(pf.params().gain, 2.0);
  EXPECT_EQ(pf.params().tangential_ratio, 0.5);
  EXPECT_THROW(pf.setGains(-1.0, 5.0, 2.0, 0.5), std::invalid_argument);
  EXPECT_THROW(pf.setGains(6.0, std::nan(""), 2.0, 0.5), std::invalid_argument);
  EXPECT_EQ(pf.params().alpha, 6.0);  // a refused change keeps the gains in force
  EXPECT_EQ(pf.params().beta, 5.0);
  // The reference keeps running from its state (no reset): still the line without obstacles.
  const Reference r = pf.next(1.0);
  EXPECT_NEAR(r.pose.y, 3.0, 1e-12);
}
