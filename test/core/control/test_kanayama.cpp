// Kanayama outer loop: hand-computed cases, analytic accelerations, Lyapunov function (4.14).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "sowing_robot/core/control/kanayama.h"

using namespace sowing_robot::core;

TEST(Kanayama, PostureErrorIsInTheRobotFrame) {
  // Robot at (1, 1) heading +90 deg, reference at (1, 3) heading 0: 2 m straight ahead, 90 deg to the right.
  const PostureError e = Kanayama::postureError({1, 3, 0}, {1, 1, M_PI / 2});
  EXPECT_NEAR(e.xe, 2.0, 1e-12);
  EXPECT_NEAR(e.ye, 0.0, 1e-12);
  EXPECT_NEAR(e.thetae, -M_PI / 2, 1e-12);
}

TEST(Kanayama, ThesisStartHandComputed) {
  // Robot at (-1, 0, 0), reference (0, 3, 0), v_r = 1, w_r = 0: xe = 1, ye = 3, thetae = 0.
  Kanayama k;
  Reference r;
  r.pose = {0, 3, 0};
  r.v = 1.0;
  const VelocityCommand c = k.compute(r, {-1, 0, 0}, 0.0, 0.0);
  EXPECT_NEAR(c.v, 1.0 + 1.0 * 1.0, 1e-12);              // v_r cos 0 + kx xe
  EXPECT_NEAR(c.omega, 0.0 + 1.0 * (1.5 * 3.0), 1e-12);  // w_r + v_r (ky ye + ktheta sin 0)
  // With v = w = 0: xe' = v_r = 1, ye' = 0, thetae' = 0 -> v_d' = kx = 1, w_d' = 0.
  EXPECT_NEAR(c.v_dot, 1.0, 1e-12);
  EXPECT_NEAR(c.omega_dot, 0.0, 1e-12);
}

TEST(Kanayama, HandComputedWithHeadingError) {
  KanayamaGains g{2.0, 3.0, 4.0};
  Kanayama k(g);
  Reference r;
  r.pose = {1, 0, 0.3};
  r.v = 0.5;
  r.omega = 0.1;
  const VelocityCommand c = k.compute(r, {0, 0, 0}, 0.0, 0.0);
  EXPECT_NEAR(c.v, 0.5 * std::cos(0.3) + 2.0 * 1.0, 1e-12);
  EXPECT_NEAR(c.omega, 0.1 + 0.5 * (3.0 * 0.0 + 4.0 * std::sin(0.3)), 1e-12);
}

TEST(Kanayama, AccelerationsMatchFiniteDifferences) {
  // Reference and robot are both unicycles driven by known smooth velocities (as eq 4.15 assumes);
  // the analytic derivative of (v_d, w_d) must match a central difference of the command along them.
  Kanayama k;
  auto vr = [](double t) { return 1 + 0.2 * t; };
  auto wr = [](double t) { return 0.15 * std::cos(0.5 * t); };
  auto v = [](double t) { return 0.8 + 0.1 * t; };
  auto w = [](double t) { return 0.2 * std::cos(t); };
  auto at = [&](double t) {
    Pose2D r{0, 3, 0}, a{-1, 0, 0.1};
    const int n = 40000;
    const double h = t / n;
    for (int i = 0; i < n; ++i) {  // midpoint rule, exact to O(h^2) and identical grids per t
      const double s = (i + 0.5) * h;
      const double tr = r.theta + 0.5 * h * wr(s), ta = a.theta + 0.5 * h * w(s);
      r.x += h * vr(s) * std::cos(tr);
      r.y += h * vr(s) * std::sin(tr);
      r.theta += h * wr(s);
      a.x += h * v(s) * std::cos(ta);
      a.y += h * v(s) * std::sin(ta);
      a.theta += h * w(s);
    }
    Reference ref;
    ref.pose = r;
    ref.v = vr(t);
    ref.omega = wr(t);
    ref.v_dot = 0.2;
    ref.omega_dot = -0.075 * std::sin(0.5 * t);
    return k.compute(ref, a, v(t), w(t));
  };
  for (double t : {0.7, 1.9, 3.2}) {
    const double h = 1e-3;
    const VelocityCommand c = at(t), p = at(t + h), m = at(t - h);
    EXPECT_NEAR(c.v_dot, (p.v - m.v) / (2 * h), 1e-4) << "t=" << t;
    EXPECT_NEAR(c.omega_dot, (p.omega - m.omega) / (2 * h), 1e-4) << "t=" << t;
  }
}

TEST(Kanayama, LyapunovFunctionNeverIncreasesOnTheKinematicLoop) {
  // eq 4.16: L0' = -kx xe^2 - v_r ktheta sin^2(thetae)/ky <= 0 when the robot realises (v_d, w_d).
  Kanayama k;
  Pose2D robot{-1, 0, 0};
  double prev = 1e9;
  const double dt = 1e-4;
  for (int i = 0; i <= 200000; ++i) {
    const double t = i * dt;
    Reference r;
    r.pose = {t, 3, 0};
    r.v = 1;
    const double l0 = k.lyapunov(Kanayama::postureError(r.pose, robot));
    ASSERT_LE(l0, prev + 1e-9) << "t=" << t;
    prev = l0;
    const VelocityCommand c = k.compute(r, robot, 0, 0);
    const double thm = robot.theta + 0.5 * dt * c.omega;
    robot.x += dt * c.v * std::cos(thm);
    robot.y += dt * c.v * std::sin(thm);
    robot.theta += dt * c.omega;
  }
  EXPECT_LT(prev, 1e-6);
}

TEST(Kanayama, ValidationRejectsNonPositiveGains) {
  EXPECT_TRUE(KanayamaGains{}.validate().empty());
  auto with = [](double kx, double ky, double ktheta) {
    KanayamaGains g;
    g.kx = kx;
    g.ky = ky;
    g.ktheta = ktheta;
    return g;
  };
  EXPECT_NE(with(0.0, 1.5, 2.2).validate().find("kx"), std::string::npos);
  EXPECT_NE(with(1.0, -1.0, 2.2).validate().find("ky"), std::string::npos);
  EXPECT_NE(with(1.0, 1.5, NAN).validate().find("ktheta"), std::string::npos);
}

TEST(Kanayama, CommandIsEquation42ToTheBit) {
  const Kanayama k;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 10000; ++i) {
    Reference r;
    r.pose = {u(rng), u(rng), i % 2 ? 0.0 : u(rng)};
    r.v = 1.0 + u(rng);
    r.omega = u(rng);
    const Pose2D a{u(rng), u(rng), 3.0 * u(rng)};
    const double v = u(rng), w = u(rng);
    const VelocityCommand one = k.compute(r, a, v, w);
    // the textbook evaluation: postureError, then cos/sin of theta_e
    const PostureError e = Kanayama::postureError(r.pose, a);
    double s, c;
    s = std::sin(e.thetae);
    c = std::cos(e.thetae);
    const KanayamaGains& g = k.gains();
    const double want_v = r.v * c + g.kx * e.xe, want_w = r.omega + r.v * (g.ky * e.ye + g.ktheta * s);
    ASSERT_EQ(std::memcmp(&one.v, &want_v, sizeof want_v), 0) << i;
    ASSERT_EQ(std::memcmp(&one.omega, &want_w, sizeof want_w), 0) << i;
  }
}
