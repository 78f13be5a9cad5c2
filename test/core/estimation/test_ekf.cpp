// The EKF of core/estimation/ekf.h: its pieces (Jacobian, a linear case), late fixes against a filter that applies
// each fix at its stamp, what it refuses, and its consistency (NEES within chi-square bounds) over long
// seeded runs with and without a fix dropout.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <random>
#include <vector>

#include "nees_bounds.h"
#include "sowing_robot/core/estimation/ekf.h"
#include "sowing_robot/core/model/sensors.h"

using namespace sowing_robot::core;
using sowing_robot::test::neesBounds;
using sowing_robot::test::NeesBounds;
using Vector6 = Eigen::Matrix<double, 6, 1>;

namespace {

EkfStepInput straight(double distance, double var_distance) {
  EkfStepInput in;
  in.distance = distance;
  in.covariance(0, 0) = var_distance;
  return in;
}

EkfParams quietParams() {
  EkfParams p;
  p.distance_noise = p.heading_noise = p.bias_walk = 0.0;
  p.gate = 0.0;
  return p;
}

}  // namespace

TEST(Ekf, DefaultsValidateAndBadValuesAreRefused) {
  EXPECT_EQ(EkfParams().validate(), "");
  EkfParams p;
  p.distance_noise = -1.0;
  EXPECT_NE(p.validate().find("estimator/odometry/distance_noise"), std::string::npos) << p.validate();
  p = EkfParams();
  p.gate = NAN;
  EXPECT_NE(p.validate().find("estimator/fix/gate"), std::string::npos);
  p = EkfParams();
  p.history_length = 1;
  EXPECT_NE(p.validate().find("estimator/history/length"), std::string::npos);
  p = EkfParams();
  p.initial_sigma_theta = INFINITY;
  EXPECT_NE(p.validate(), "");
  EXPECT_THROW(Ekf{p}, std::invalid_argument);
}

TEST(Ekf, MotionJacobianMatchesFiniteDifferences) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uni(-3.0, 3.0);
  for (int trial = 0; trial < 50; ++trial) {
    Vector6 a;
    for (int i = 0; i < 6; ++i) a(i) = uni(rng);
    a(2) = 0.9 * uni(rng);  // keep theta + d away from the wrap at pi for the differences
    a(4) = 0.1 * uni(rng);
    const Eigen::Matrix<double, 4, 6> f = Ekf::motionJacobian(a);
    for (int j = 0; j < 6; ++j) {
      const double h = 1e-6;
      Vector6 p = a, m = a;
      p(j) += h;
      m(j) -= h;
      const Ekf::Vector df = (Ekf::motion(p) - Ekf::motion(m)) / (2.0 * h);
      for (int i = 0; i < 4; ++i) EXPECT_NEAR(f(i, j), df(i), 1e-7) << "d f" << i << " / d a" << j;
    }
  }
}

TEST(Ekf, StraightLineIsTheScalarKalmanFilter) {
  // Heading 0 and known exactly, no gyro: x is a random walk with the distance variance, y is untouched,
  // and a fix is the scalar Kalman update.
  EkfParams p = quietParams();
  p.initial_sigma_theta = 0.0;
  p.initial_sigma_bias = 0.0;
  p.initial_sigma_xy = 0.1;
  Ekf ekf(p);
  ekf.reset(0.0, Pose2D{1.0, 2.0, 0.0});
  const double q = 1e-4, dt = 0.01;
  for (int k = 1; k <= 100; ++k) ASSERT_TRUE(ekf.predict(k * dt, straight(0.005, q)));
  double var = 0.01 + 100 * q;
  EXPECT_NEAR(ekf.mean()(0), 1.5, 1e-12);
  EXPECT_NEAR(ekf.mean()(1), 2.0, 1e-15);
  EXPECT_NEAR(ekf.covariance()(0, 0), var, 1e-15);
  EXPECT_NEAR(ekf.covariance()(1, 1), 0.01, 1e-15);
  EkfFix fix;
  fix.stamp = 1.0;
  fix.xy << 1.6, 1.9;
  const double r = 0.0004;
  fix.covariance = r * Eigen::Matrix2d::Identity();
  ASSERT_EQ(ekf.fuse(fix), FixOutcome::APPLIED);
  const double gain_x = var / (var + r), gain_y = 0.01 / (0.01 + r);
  EXPECT_NEAR(ekf.mean()(0), 1.5 + gain_x * 0.1, 1e-12);
  EXPECT_NEAR(ekf.mean()(1), 2.0 - gain_y * 0.1, 1e-12);
  EXPECT_NEAR(ekf.covariance()(0, 0), var * r / (var + r), 1e-15);
  EXPECT_NEAR(ekf.covariance()(1, 1), 0.01 * r / (0.01 + r), 1e-15);
  EXPECT_NEAR(ekf.mean()(2), 0.0, 1e-15);
}

TEST(Ekf, StandingStillTheGyroBiasIsTheMeanRate) {
  // Encoders say "no turn" exactly; the gyro reads bias + noise: with a wide prior and no bias walk the
  // bias estimate is the mean of the readings and its variance sigma_r^2 / N.
  EkfParams p = quietParams();
  p.initial_sigma_bias = 10.0;
  Ekf ekf(p);
  ekf.reset(0.0, Pose2D{});
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  double sum = 0.0;
  const int n = 2000;
  for (int k = 1; k <= n; ++k) {
    EkfStepInput in;
    in.has_rate = true;
    in.rate = 0.02 + noise(rng);
    in.rate_variance = 1e-4;
    sum += in.rate;
    ASSERT_TRUE(ekf.predict(k * 1e-3, in));
  }
  EXPECT_NEAR(ekf.mean()(Ekf::BIAS), sum / n, 1e-6);
  EXPECT_NEAR(ekf.covariance()(Ekf::BIAS, Ekf::BIAS), 1e-4 / n, 1e-9);
  EXPECT_NEAR(ekf.mean()(Ekf::THETA), 0.0, 1e-12);  // the encoders hold the heading
  // Without bias estimation the bias stays 0 with no variance.
  p.estimate_bias = false;
  Ekf pinned(p);
  pinned.reset(0.0, Pose2D{}, 0.5);
  EkfStepInput in;
  in.has_rate = true;
  in.rate = 0.02;
  in.rate_variance = 1e-4;
  ASSERT_TRUE(pinned.predict(1e-3, in));
  EXPECT_EQ(pinned.mean()(Ekf::BIAS), 0.0);
  EXPECT_EQ(pinned.covariance().row(Ekf::BIAS).norm(), 0.0);
}

namespace {

/// Seeded synthetic inputs drawn exactly from the filter's own noise model (Gaussian increments whose
/// variances are the ones the filter is told), for the tests of the filter's algebra. The sensor models
/// of the plant (quantised encoders etc.) are core/model/sensors.h's.
struct GaussianWorld {
  explicit GaussianWorld(std::uint64_t seed, const EkfParams& p) : rng(seed), params(p) {}
  std::mt19937_64 rng;
  std::normal_distribution<double> n{0.0, 1.0};
  EkfParams params;
  Ekf::Vector truth = (Ekf::Vector() << 0.0, 0.0, 0.0, 0.01).finished();
  double rate_sigma = 0.005;
  double fix_sigma = 0.02;

  /// One step at time t of length dt: the truth moves, the measurements are returned.
  EkfStepInput step(double t, double dt) {
    const double v = 0.6, omega = 0.3 * std::sin(0.2 * t);
    const double u_nom = v * dt, d_nom = omega * dt;
    EkfStepInput in;
    // Measured increments; the truth differs by the process noise the filter assumes (|u| rolled).
    in.distance = u_nom;
    in.dtheta = d_nom;
    const double su = params.distance_noise * std::sqrt(u_nom), sd = params.heading_noise * std::sqrt(u_nom);
    const double u = u_nom + su * n(rng), d = d_nom + sd * n(rng);
    Vector6 a;
    a << truth, d, u;
    truth = Ekf::motion(a);
    truth(Ekf::BIAS) += params.bias_walk * std::sqrt(dt) * n(rng);
    in.has_rate = true;
    in.rate = d / dt + truth(Ekf::BIAS) + rate_sigma * n(rng);
    in.rate_variance = rate_sigma * rate_sigma;
    return in;
  }
  EkfFix fix(double t) {
    EkfFix f;
    f.stamp = t;
    f.xy << truth(0) + fix_sigma * n(rng), truth(1) + fix_sigma * n(rng);
    f.covariance = fix_sigma * fix_sigma * Eigen::Matrix2d::Identity();
    return f;
  }
};

double nees(const Ekf& ekf, const Ekf::Vector& truth) {
  Ekf::Vector e = truth - ekf.mean();
  e(Ekf::THETA) = wrapAngle(e(Ekf::THETA));
  return e.dot(ekf.covariance().ldlt().solve(e));
}

struct NeesRun {
  std::vector<double> nees;      // at each checkpoint
  std::vector<double> sigma_xy;  // sqrt(trace of the position covariance / 2) at each checkpoint
  std::vector<double> error_xy;  // position error at each checkpoint
};

/// One seeded run of `seconds` at 1 kHz, fixes at 10 Hz stamped at measurement and applied
/// `latency` later (through FixQueue), none in [dropout_start, dropout_end); checkpoints every second.
NeesRun runNees(std::uint64_t seed, const EkfParams& filter_params, const EkfParams& world_params, double seconds,
                double latency, double dropout_start = 0.0, double dropout_end = 0.0) {
  GaussianWorld world(seed, world_params);
  Ekf ekf(filter_params);
  std::normal_distribution<double> n(0.0, 1.0);
  // Start from a draw of the initial covariance around the truth.
  Ekf::Vector start = world.truth;
  start(0) += filter_params.initial_sigma_xy * n(world.rng);
  start(1) += filter_params.initial_sigma_xy * n(world.rng);
  start(2) += filter_params.initial_sigma_theta * n(world.rng);
  start(3) += filter_params.initial_sigma_bias * n(world.rng);
  ekf.reset(0.0, Pose2D{start(0), start(1), start(2)}, start(3));
  FixQueue queue(latency);
  NeesRun out;
  const double dt = 1e-3;
  const int steps = static_cast<int>(std::lround(seconds / dt));
  for (int k = 1; k <= steps; ++k) {
    const double t = k * dt;
    const EkfStepInput in = world.step(t, dt);
    EXPECT_TRUE(ekf.predict(t, in));
    if (k % 100 == 0 && !(t >= dropout_start && t < dropout_end)) queue.push(world.fix(t));
    for (const EkfFix& f : queue.due(t)) ekf.fuse(f);
    if (k % 1000 == 0) {
      out.nees.push_back(nees(ekf, world.truth));
      out.sigma_xy.push_back(std::sqrt(0.5 * ekf.covariance().topLeftCorner<2, 2>().trace()));
      out.error_xy.push_back((world.truth.head<2>() - ekf.mean().head<2>()).norm());
    }
  }
  EXPECT_EQ(ekf.counts().refused(), 0) << "seed " << seed << ": " << ekf.counts().gated << " gated";
  return out;
}

/// Counts the checkpoints whose mean NEES over the runs is outside the two-sided 99 % interval of
/// chi2(4 M) / M; grand_mean gets the mean over runs and checkpoints. The checkpoints of one run are
/// correlated (through a dropout strongly), so the grand mean is held to the 95 % interval of one
/// checkpoint's mean (an average of them varies no more than one does): valid, if not tight.
int checkNees(const std::vector<NeesRun>& runs, double& grand_mean) {
  const std::size_t m = runs.size(), k = runs[0].nees.size();
  const NeesBounds b = neesBounds(m, 2.576);
  int outside = 0;
  double sum = 0.0;
  for (std::size_t c = 0; c < k; ++c) {
    double mean = 0.0;
    for (const NeesRun& r : runs) mean += r.nees[c] / m;
    sum += mean;
    if (mean < b.lo || mean > b.hi) ++outside;
  }
  grand_mean = sum / k;
  return outside;
}

EkfParams worldParams() {
  EkfParams p;
  p.distance_noise = 0.02;
  p.heading_noise = 0.02;
  p.bias_walk = 2e-4;
  p.gate = 0.0;  // a gate truncates the innovations the NEES is about (one genuine 5-sigma fix in 24000 here)
  return p;
}

}  // namespace

TEST(Ekf, LateFixEqualsTheFixAppliedAtItsStamp) {
  const EkfParams p = worldParams();
  GaussianWorld world(11, p);
  Ekf reference(p), late(p);
  reference.reset(0.0, Pose2D{});
  late.reset(0.0, Pose2D{});
  FixQueue queue(0.137);  // applied 137 steps late, not a multiple of the fix period
  std::vector<EkfFix> out_of_order;
  for (int k = 1; k <= 5000; ++k) {
    const double t = k * 1e-3;
    const EkfStepInput in = world.step(t, 1e-3);
    ASSERT_TRUE(reference.predict(t, in));
    ASSERT_TRUE(late.predict(t, in));
    if (k % 100 == 0) {
      const EkfFix f = world.fix(t);
      ASSERT_EQ(reference.fuse(f), FixOutcome::APPLIED);
      queue.push(f);
    }
    for (const EkfFix& f : queue.due(t)) ASSERT_EQ(late.fuse(f), FixOutcome::APPLIED);
  }
  for (const EkfFix& f : queue.due(1e9)) ASSERT_EQ(late.fuse(f), FixOutcome::APPLIED);
  EXPECT_EQ(late.counts().applied, reference.counts().applied);
  EXPECT_LT((late.mean() - reference.mean()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((late.covariance() - reference.covariance()).cwiseAbs().maxCoeff(), 1e-15);
  // And two late fixes taken in the wrong order end where the in-order ones do.
  Ekf a(p), b(p);
  a.reset(0.0, Pose2D{});
  b.reset(0.0, Pose2D{});
  std::vector<EkfFix> fixes;
  for (int k = 1; k <= 400; ++k) {
    const double t = k * 1e-3;
    const EkfStepInput in = world.step(t, 1e-3);
    a.predict(t, in);
    b.predict(t, in);
    if (k == 100 || k == 200) fixes.push_back(world.fix(t));
  }
  a.fuse(fixes[0]);
  a.fuse(fixes[1]);
  b.fuse(fixes[1]);
  b.fuse(fixes[0]);
  EXPECT_LT((a.mean() - b.mean()).cwiseAbs().maxCoeff(), 1e-3);              // the order of two updates: not exact,
  EXPECT_LT((a.covariance() - b.covariance()).cwiseAbs().maxCoeff(), 1e-6);  // but the same information
}

TEST(Ekf, RefusesAndCountsBadFixes) {
  EkfParams p = worldParams();
  p.history_length = 100;
  p.gate = EkfParams().gate;
  Ekf ekf(p);
  EkfFix f;
  f.covariance = 4e-4 * Eigen::Matrix2d::Identity();
  EXPECT_EQ(ekf.fuse(f), FixOutcome::REFUSED_INVALID);  // before reset
  ekf.reset(0.0, Pose2D{});
  GaussianWorld world(5, p);
  for (int k = 1; k <= 300; ++k) ASSERT_TRUE(ekf.predict(k * 1e-3, world.step(k * 1e-3, 1e-3)));
  EXPECT_EQ(ekf.historySize(), 100u);
  EXPECT_NEAR(ekf.oldestTime(), 0.201, 1e-12);
  const Ekf::Vector before = ekf.mean();
  f = world.fix(0.150);  // older than the history
  EXPECT_EQ(ekf.fuse(f), FixOutcome::REFUSED_TOO_OLD);
  f = world.fix(0.350);  // newer than the estimate
  EXPECT_EQ(ekf.fuse(f), FixOutcome::REFUSED_FUTURE);
  f = world.fix(0.250);
  f.xy(0) = NAN;
  EXPECT_EQ(ekf.fuse(f), FixOutcome::REFUSED_INVALID);
  f = world.fix(0.250);
  f.covariance(0, 0) = -1.0;
  EXPECT_EQ(ekf.fuse(f), FixOutcome::REFUSED_INVALID);
  f = world.fix(0.250);
  f.xy(0) += 5.0;  // 5 m off with a few cm of covariance: far outside the gate
  EXPECT_EQ(ekf.fuse(f), FixOutcome::REFUSED_GATE);
  EXPECT_EQ(ekf.mean(), before);  // nothing refused changed the estimate
  EXPECT_EQ(ekf.counts().too_old, 1);
  EXPECT_EQ(ekf.counts().future, 1);
  EXPECT_EQ(ekf.counts().invalid, 3);  // with the one before reset
  EXPECT_EQ(ekf.counts().gated, 1);
  EXPECT_EQ(ekf.counts().applied, 0);
  EXPECT_EQ(ekf.fuse(world.fix(0.201)), FixOutcome::APPLIED);  // the oldest kept state still takes one
  // Bad step inputs are refused and change nothing.
  EkfStepInput in = world.step(0.301, 1e-3);
  in.distance = NAN;
  EXPECT_FALSE(ekf.predict(0.301, in));
  in = world.step(0.301, 1e-3);
  in.rate_variance = -1.0;
  EXPECT_FALSE(ekf.predict(0.301, in));
  EXPECT_FALSE(ekf.predict(0.300, world.step(0.300, 1e-3)));  // not after time()
  EXPECT_DOUBLE_EQ(ekf.time(), 0.300);
}

TEST(Ekf, FixQueueHandsOutByStampPlusDelay) {
  FixQueue q(0.1, 3);
  EkfFix f;
  for (double s : {0.3, 0.1, 0.2}) {
    f.stamp = s;
    q.push(f);
  }
  EXPECT_TRUE(q.due(0.199).empty());
  auto due = q.due(0.3);
  ASSERT_EQ(due.size(), 2u);
  EXPECT_EQ(due[0].stamp, 0.1);
  EXPECT_EQ(due[1].stamp, 0.2);
  for (double s : {0.4, 0.5, 0.6}) {
    f.stamp = s;
    q.push(f);
  }
  EXPECT_EQ(q.dropped(), 1);  // 0.3 went
  EXPECT_EQ(q.due(10.0).front().stamp, 0.4);
}

TEST(Ekf, NeesWithinChiSquareBoundsOverLongRuns) {
  const EkfParams p = worldParams();
  std::vector<NeesRun> runs;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) runs.push_back(runNees(seed, p, p, 60.0, 0.1));
  double grand = 0.0;
  const int outside = checkNees(runs, grand);
  const NeesBounds b = neesBounds(runs.size());
  std::printf(
      "mean NEES %.3f over %zu runs x %zu checkpoints (95 %% interval [%.3f, %.3f]), %d checkpoints "
      "outside their 99 %% interval\n",
      grand, runs.size(), runs[0].nees.size(), b.lo, b.hi, outside);
  EXPECT_LE(outside, 2) << "checkpoints whose mean NEES is outside the 99 % interval";
  EXPECT_GT(grand, b.lo);
  EXPECT_LT(grand, b.hi);
  // The same runs repeat bit for bit.
  const NeesRun again = runNees(3, p, p, 60.0, 0.1);
  EXPECT_EQ(again.nees, runs[2].nees);
}

TEST(Ekf, OverconfidentFilterFailsTheNeesBound) {
  // What the bound protects: a filter told a tenth of the true process noise is caught.
  const EkfParams world = worldParams();
  EkfParams filter = world;
  filter.distance_noise *= 0.1;
  filter.heading_noise *= 0.1;
  filter.gate = 0.0;
  std::vector<NeesRun> runs;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) runs.push_back(runNees(seed, filter, world, 30.0, 0.1));
  double grand = 0.0;
  checkNees(runs, grand);
  EXPECT_GT(grand, neesBounds(runs.size()).hi);
}

TEST(Ekf, ThroughAFixDropoutTheCovarianceGrowsHoldsTheErrorAndConvergesAfter) {
  const EkfParams p = worldParams();
  std::vector<NeesRun> runs;
  // 60 s, no fix in [20, 40) s.
  for (std::uint64_t seed = 100; seed < 140; ++seed) runs.push_back(runNees(seed, p, p, 60.0, 0.1, 20.0, 40.0));
  double grand = 0.0;
  const int outside = checkNees(runs, grand);
  const NeesBounds b = neesBounds(runs.size());
  std::printf("dropout: mean NEES %.3f (95 %% interval [%.3f, %.3f]), %d checkpoints outside their 99 %% interval\n",
              grand, b.lo, b.hi, outside);
  EXPECT_LE(outside, 2);
  EXPECT_GT(grand, b.lo);
  EXPECT_LT(grand, b.hi);
  // Checkpoint c is at t = c + 1 s.
  double before = 0.0, end_of_dropout = 0.0, after = 0.0, err_in = 0.0, sig_in = 0.0;
  for (const NeesRun& r : runs) {
    before += r.sigma_xy[18] / runs.size();          // 19 s
    end_of_dropout += r.sigma_xy[38] / runs.size();  // 39 s
    after += r.sigma_xy[44] / runs.size();           // 45 s
    for (int c = 20; c < 39; ++c) {
      err_in += r.error_xy[c] * r.error_xy[c];
      sig_in += r.sigma_xy[c] * r.sigma_xy[c];
    }
  }
  std::printf("position sigma: %.4f m before, %.4f m at the end of the dropout, %.4f m 5 s after\n", before,
              end_of_dropout, after);
  EXPECT_GT(end_of_dropout, 3.0 * before);  // it grows
  for (const NeesRun& r : runs)
    for (int c = 20; c < 39; ++c) EXPECT_LE(r.sigma_xy[c], r.sigma_xy[c + 1] * (1.0 + 1e-9));  // monotonically
  EXPECT_LT(after, 1.5 * before);                                                              // and comes back
  // The position error through the dropout is of the size the covariance says (RMS ratio near 1).
  const double ratio = std::sqrt(err_in / (2.0 * sig_in));
  EXPECT_GT(ratio, 0.8);
  EXPECT_LT(ratio, 1.2);
}

namespace {

/// The EKF fed by core/model/sensors.h: a kinematic truth whose wheels slip by N(0, k |travel|) per step (the
/// model sensors/encoder/travel_variance states), read by the quantised encoders, the biased gyro and the
/// late, 10 Hz position fix (fused when the sensor delivers it, latency after its stamp). The filter is
/// told the world's model: the slip's covariance from the wheels' travel, and no bias walk (the sensor's
/// bias, sensors/imu/bias, is constant; told 1e-4 rad/s/sqrt(s) it is conservative, NEES ~2.9).
struct SensorRun {
  std::vector<double> nees, sigma_xy, error_xy;
  FixCounts counts;
  double max_error = 0.0;
  Ekf::Vector ratio_sum = Ekf::Vector::Zero();  ///< sum over the checkpoints of e_i^2 / P_ii (per state)
  double along_sum = 0.0;                       ///< sum over the checkpoints of the along-track error [m]
};

/// draw_start: the filter starts from a draw of its initial covariance around the truth (as runNees), for
/// the NEES; otherwise at the true pose with bias 0 (the position error then measures the filter alone).
SensorRun runWithSensors(std::uint64_t seed, double seconds, double dropout_start = 0.0, double dropout = 0.0,
                         bool draw_start = false) {
  const double R = 0.095, L = 0.24, dt = 1e-3;
  SensorParams sp;
  sp.seed = seed;
  sp.fix.dropout_start = dropout_start;
  sp.fix.dropout_duration = dropout;
  const double k = sp.encoder.travel_variance;
  EncoderOdometry encoders(sp, R, L);
  YawRateSensor gyro(sp);
  PositionFixSensor fixes(sp);
  EkfParams ep;
  ep.distance_noise = ep.heading_noise = 0.0;  // the wheel-travel covariance below is the whole model
  ep.bias_walk = 0.0;                          // sensors/imu/bias is constant
  ep.gate = 0.0;
  Ekf ekf(ep);
  std::mt19937_64 slip_rng = sensorGenerator(seed, 99);
  std::normal_distribution<double> n(0.0, 1.0);
  Pose2D truth{0.0, 0.0, 0.0};
  double phi_r = 0.0, phi_l = 0.0;
  encoders.reset(truth, phi_r, phi_l);
  fixes.reset(0.0);
  if (draw_start) {
    std::mt19937_64 start_rng = sensorGenerator(seed, 98);
    std::normal_distribution<double> start_n(0.0, 1.0);
    const double ex = start_n(start_rng), ey = start_n(start_rng), et = start_n(start_rng), eb = start_n(start_rng);
    ekf.reset(0.0, Pose2D{ep.initial_sigma_xy * ex, ep.initial_sigma_xy * ey, ep.initial_sigma_theta * et},
              sp.imu.bias + ep.initial_sigma_bias * eb);
  } else {
    ekf.reset(0.0, truth, 0.0);  // the bias starts unknown (initial sigma_bias 0.01 rad/s against 0.002)
  }
  SensorRun out;
  const int steps = static_cast<int>(std::lround(seconds / dt));
  for (int i = 1; i <= steps; ++i) {
    const double t = i * dt;
    const double v = 0.6, omega = 0.3 * std::sin(0.2 * t);
    const double wr = (v + L * omega) * dt, wl = (v - L * omega) * dt;  // wheel travels R dphi
    phi_r += wr / R;
    phi_l += wl / R;
    const double ur = wr + std::sqrt(k * std::fabs(wr)) * n(slip_rng),
                 ul = wl + std::sqrt(k * std::fabs(wl)) * n(slip_rng);
    const double ds = 0.5 * (ur + ul), dth = (ur - ul) / (2.0 * L), mid = truth.theta + 0.5 * dth;
    truth = {truth.x + ds * std::cos(mid), truth.y + ds * std::sin(mid), wrapAngle(truth.theta + dth)};
    const Odometry2D odo = encoders.update(phi_r, phi_l, dt);
    EkfStepInput in;
    in.distance = odo.delta_s;
    in.dtheta = odo.delta_theta;
    // The slip's covariance from the wheels' travel over the encoders' velocity window, not from this
    // step's quantised increments (wheelTravelCovariance says why: those made the estimate lag 7 mm).
    const double travel_r = (odo.v + L * odo.omega) * dt, travel_l = (odo.v - L * odo.omega) * dt;
    in.covariance = wheelTravelCovariance(travel_r, travel_l, L, k) +
                    encoderIncrementCovariance(ep.increment_sigma, L);  // as state_estimator adds it
    in.has_rate = true;
    in.rate = gyro.measure(dth / dt);
    in.rate_variance = gyro.noise() * gyro.noise();
    EXPECT_TRUE(ekf.predict(t, in));
    fixes.sample(t, truth);
    for (const FixMeasurement& m : fixes.due(t)) {
      EkfFix f;
      f.stamp = m.stamp;
      f.xy = m.xy;
      f.covariance = m.sigma * m.sigma * Eigen::Matrix2d::Identity();
      EXPECT_EQ(ekf.fuse(f), FixOutcome::APPLIED);
    }
    const Ekf::Vector x = (Ekf::Vector() << truth.x, truth.y, truth.theta, sp.imu.bias).finished();
    const double err = (x.head<2>() - ekf.mean().head<2>()).norm();
    out.max_error = std::max(out.max_error, err);
    if (i % 1000 == 0) {
      out.nees.push_back(nees(ekf, x));
      out.sigma_xy.push_back(std::sqrt(0.5 * ekf.covariance().topLeftCorner<2, 2>().trace()));
      out.error_xy.push_back(err);
      Ekf::Vector e = x - ekf.mean();
      e(Ekf::THETA) = wrapAngle(e(Ekf::THETA));
      out.ratio_sum += e.cwiseProduct(e).cwiseQuotient(ekf.covariance().diagonal());
      out.along_sum += e(Ekf::X) * std::cos(truth.theta) + e(Ekf::Y) * std::sin(truth.theta);
    }
  }
  out.counts = ekf.counts();
  return out;
}

}  // namespace

// Consistency fed by core/model/sensors.h (NEES within its bounds over a long run): 40 runs of 60 s
// (as NeesWithinChiSquareBoundsOverLongRuns), each starting from a draw of the initial covariance (started
// at the truth, the first checkpoint's NEES is ~2.4: the covariance then says more than the error), and
// per state (squared error over the marginal variance, 1 for a consistent filter; its mean over 2,400
// checkpoints varies by ~0.05), so that an overconfident position cannot hide behind a conservative bias.
// What it caught: with the slip's covariance computed from the step's quantised increments (2 or 3
// ticks per wheel) the gyro update shortened the distance by 7.4 um per step on average, the estimate
// lagged the truth by 7 mm along the track, and the mean NEES was 5.7 against [3.05, 5.07] over 30 runs
// (x 1.9, y 2.1); see wheelTravelCovariance. Its slip case (one wheel, then both wheels spinning, with the
// slip-aware filter of estimator/slip/detect) is test_ekf_slip's EkfSlipWithSensors.
TEST(EkfWithSensors, NeesWithinChiSquareBounds) {
  std::vector<NeesRun> runs;
  Ekf::Vector ratio = Ekf::Vector::Zero();
  double along = 0.0, checkpoints = 0.0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const SensorRun r = runWithSensors(seed, 60.0, 0.0, 0.0, true);
    runs.push_back({r.nees, r.sigma_xy, r.error_xy});
    ratio += r.ratio_sum;
    along += r.along_sum;
    checkpoints += static_cast<double>(r.nees.size());
  }
  ratio /= checkpoints;
  along /= checkpoints;
  double grand = 0.0;
  const int outside = checkNees(runs, grand);
  const NeesBounds b = neesBounds(runs.size());
  std::printf(
      "with core/model/sensors.h: mean NEES %.3f over %zu runs (95 %% interval [%.3f, %.3f]), %d outside; per state "
      "x %.2f y %.2f theta %.2f bias %.2f; mean along-track error %.2f mm\n",
      grand, runs.size(), b.lo, b.hi, outside, ratio(Ekf::X), ratio(Ekf::Y), ratio(Ekf::THETA), ratio(Ekf::BIAS),
      1e3 * along);
  EXPECT_LE(outside, 2);
  EXPECT_GT(grand, b.lo);
  EXPECT_LT(grand, b.hi);
  for (int i = Ekf::X; i <= Ekf::THETA; ++i) {
    EXPECT_GT(ratio(i), 0.7) << "state " << i;
    EXPECT_LT(ratio(i), 1.3) << "state " << i;
  }
  // One bias error per run, slowly varying: fewer independent samples, a wider band.
  EXPECT_GT(ratio(Ekf::BIAS), 0.5);
  EXPECT_LT(ratio(Ekf::BIAS), 1.5);
}

TEST(EkfWithSensors, LateFixesAllAppliedErrorBoundedSeedsReproduce) {
  double worst = 0.0, grand = 0.0;
  std::vector<NeesRun> runs;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const SensorRun r = runWithSensors(seed, 60.0);
    EXPECT_EQ(r.counts.refused(), 0);
    EXPECT_GE(r.counts.applied, 599);  // 10 Hz over 60 s, the last one possibly still in flight
    worst = std::max(worst, r.max_error);
    runs.push_back({r.nees, r.sigma_xy, r.error_xy});
  }
  checkNees(runs, grand);
  std::printf("with core/model/sensors.h: worst position error %.4f m over 10 runs of 60 s; mean NEES %.2f\n", worst,
              grand);
  EXPECT_LT(worst, 0.06);  // 3 fix sigmas
  EXPECT_EQ(runWithSensors(4, 60.0).nees, runs[3].nees);
}

TEST(EkfWithSensors, ThroughTheSensorsDropoutTheCovarianceGrowsAndComesBack) {
  std::vector<NeesRun> runs;
  for (std::uint64_t seed = 50; seed < 60; ++seed) {
    const SensorRun r = runWithSensors(seed, 60.0, 20.0, 20.0);
    EXPECT_EQ(r.counts.refused(), 0);
    runs.push_back({r.nees, r.sigma_xy, r.error_xy});
  }
  double before = 0.0, end_of_dropout = 0.0, after = 0.0, worst_in = 0.0;
  for (const NeesRun& r : runs) {
    before += r.sigma_xy[18] / runs.size();
    end_of_dropout += r.sigma_xy[38] / runs.size();
    after += r.sigma_xy[44] / runs.size();
    for (int c = 20; c < 39; ++c) {
      EXPECT_LE(r.sigma_xy[c], r.sigma_xy[c + 1] * (1.0 + 1e-9));
      worst_in = std::max(worst_in, r.error_xy[c]);
    }
  }
  std::printf(
      "with core/model/sensors.h, dropout 20-40 s: position sigma %.4f m before, %.4f m at its end, %.4f m 5 s "
      "after; worst error in it %.4f m\n",
      before, end_of_dropout, after, worst_in);
  EXPECT_GT(end_of_dropout, 3.0 * before);
  EXPECT_LT(after, 1.5 * before);
  EXPECT_LT(worst_in, 0.1);  // 0.056 m seen (0.16 m with the slip's covariance from the quantised increments)
}

// The quantisation covariance of one step is that of (d_r + d_l)/2 and (d_r - d_l)/(2L) for two
// independent wheel increments of std s: J diag(s², s²) Jᵀ.
TEST(EkfInputs, EncoderIncrementCovarianceIsThatOfTheTwoWheels) {
  const double s = 1.19e-4, L = 0.24;
  Eigen::Matrix2d J;
  J << 0.5, 0.5, 1.0 / (2.0 * L), -1.0 / (2.0 * L);
  const Eigen::Matrix2d expected = J * (s * s * Eigen::Matrix2d::Identity()) * J.transpose();
  const Eigen::Matrix2d c = encoderIncrementCovariance(s, L);
  EXPECT_LT((c - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  EXPECT_GT(c(1, 1), 0.0);
  EXPECT_EQ(encoderIncrementCovariance(0.0, L), Eigen::Matrix2d::Zero());
}

namespace {

/// A filter whose encoders count 50 % more distance than the robot travels (spinning wheels) for 10 s,
/// with a fix of the truth every 0.1 s (applied 0.1 s late, as the node does): the largest position
/// error over the last 5 s, and the counts.
struct SlipRun {
  double late_error = 0.0;
  FixCounts counts;
  Ekf::Vector mean;
  Ekf::Matrix cov;
};

SlipRun runThroughSlip(int reanchor_after, double slip_inflation = 1.0, double slip = 1.5) {
  EkfParams p;
  p.reanchor_after = reanchor_after;
  p.slip_inflation = slip_inflation;
  Ekf ekf(p);
  const double dt = 1e-3, v = 1.0;
  ekf.reset(0.0, Pose2D{0.0, 0.0, 0.0});
  std::deque<EkfFix> pending;
  SlipRun out;
  for (int i = 1; i <= 10000; ++i) {
    const double t = i * dt, x = v * t;
    EkfStepInput in;
    in.distance = slip * v * dt;  // the encoders' distance under slip
    in.covariance = encoderIncrementCovariance(p.increment_sigma, 0.24);
    in.has_rate = true;
    in.rate = 0.0;
    in.rate_variance = 1e-4;
    EXPECT_TRUE(ekf.predict(t, in));
    if (i % 100 == 0) {
      EkfFix f;
      f.stamp = t;
      f.xy << x, 0.0;
      f.covariance = 0.02 * 0.02 * Eigen::Matrix2d::Identity();
      pending.push_back(f);
    }
    while (!pending.empty() && pending.front().stamp + 0.1 <= t + 1e-9) {
      ekf.fuse(pending.front());
      pending.pop_front();
    }
    if (t >= 5.0) out.late_error = std::max(out.late_error, std::hypot(ekf.mean()(Ekf::X) - x, ekf.mean()(Ekf::Y)));
  }
  out.counts = ekf.counts();
  out.mean = ekf.mean();
  out.cov = ekf.covariance();
  return out;
}

}  // namespace

// Slip makes the estimate outrun its covariance (here with the slip inflation off, to see the re-anchoring
// alone); the gate then refuses every fix of the truth for ever,
// unless the filter re-anchors after fix/reanchor_after gated fixes in a row.
TEST(EkfReanchor, AfterGatedFixesInARowTheFixBecomesThePosition) {
  const SlipRun never = runThroughSlip(0), after5 = runThroughSlip(5);
  std::printf(
      "through 10 s of 50 %% slip: without re-anchoring %ld of %ld fixes gated, error %.2f m late on; "
      "re-anchoring after 5: %ld re-anchored, %ld gated, error %.3f m\n",
      never.counts.gated, never.counts.gated + never.counts.applied, never.late_error, after5.counts.reanchored,
      after5.counts.gated, after5.late_error);
  EXPECT_EQ(never.counts.reanchored, 0);
  EXPECT_GT(never.late_error, 1.0);  // lost
  EXPECT_GT(after5.counts.reanchored, 0);
  // At most ~(5 gated + 1) fix intervals + the 0.1 s delay of 0.5 m/s drift: 0.35 m, plus the drift that
  // the fixes applied after an anchor only partly correct.
  EXPECT_LT(after5.late_error, 0.5);
  EXPECT_LE(after5.counts.gated, 5 * (after5.counts.reanchored + 1));
}

// The slip inflation (the default): the first gated fix raises the distance noise, the next fixes pass the
// gate and hold the estimate to them: the error stays at the drift between two fixes plus the fix's delay
// (0.5 m/s x 0.2 s), not metres.
TEST(EkfSlip, AfterAGatedFixTheInflatedDistanceNoiseLetsTheFixesIn) {
  const double inflation = EkfParams().slip_inflation;
  ASSERT_GT(inflation, 1.0);
  const SlipRun on = runThroughSlip(0, inflation), off = runThroughSlip(0, 1.0);
  std::printf(
      "through 10 s of 50 %% slip: slip inflation x%g: %ld of %ld fixes gated, %ld onsets, error %.3f m; off: "
      "%ld gated, error %.2f m\n",
      inflation, on.counts.gated, on.counts.gated + on.counts.applied, on.counts.slip_onsets, on.late_error,
      off.counts.gated, off.late_error);
  EXPECT_GT(off.late_error, 1.0);  // lost
  EXPECT_LT(on.late_error, 0.15);
  EXPECT_GE(on.counts.slip_onsets, 1);
  EXPECT_LE(on.counts.gated, 5);
  EXPECT_EQ(off.counts.slip_onsets, 0);
}

// Without a gated fix the inflation never starts: the estimate is the one without it, to the bit.
TEST(EkfSlip, WithoutAGatedFixNothingChanges) {
  const SlipRun on = runThroughSlip(5, 100.0, 1.0), off = runThroughSlip(5, 1.0, 1.0);
  EXPECT_EQ(on.counts.gated, 0);
  EXPECT_EQ(on.counts.slip_onsets, 0);
  EXPECT_TRUE(on.mean == off.mean);
  EXPECT_TRUE(on.cov == off.cov);
}

// A fix stamped before a re-anchoring one but arriving after it makes the filter propagate its history
// again: the re-anchoring is replayed as a re-anchoring (not as an ordinary update), so it still holds.
TEST(EkfReanchor, ReplayedAsAReanchorWhenAnEarlierStampedFixComesLate) {
  EkfParams p;
  p.reanchor_after = 1;
  p.gate = 25.0;
  Ekf ekf(p);
  ekf.reset(0.0, Pose2D{0.0, 0.0, 0.0});
  EkfStepInput in;
  in.distance = 1e-3;  // 1 m/s along x
  for (int i = 1; i <= 50; ++i) ASSERT_TRUE(ekf.predict(i * 1e-3, in));
  EkfFix far;
  far.xy << 5.0, 5.0;
  far.covariance = 1e-4 * Eigen::Matrix2d::Identity();
  far.stamp = 0.01;
  EXPECT_EQ(ekf.fuse(far), FixOutcome::REFUSED_GATE);
  far.stamp = 0.02;
  EXPECT_EQ(ekf.fuse(far), FixOutcome::REANCHORED);
  EXPECT_NEAR(ekf.mean()(Ekf::X), 5.03, 1e-9);  // the fix, then 30 steps of 1 mm
  EXPECT_NEAR(ekf.mean()(Ekf::Y), 5.0, 1e-9);
  EkfFix earlier;  // where the estimate was at 0.015 s: inside the gate there
  earlier.stamp = 0.015;
  earlier.xy << 0.015, 0.0;
  earlier.covariance = far.covariance;
  EXPECT_EQ(ekf.fuse(earlier), FixOutcome::APPLIED);
  EXPECT_NEAR(ekf.mean()(Ekf::X), 5.03, 1e-9);
  EXPECT_NEAR(ekf.mean()(Ekf::Y), 5.0, 1e-9);
  EXPECT_EQ(ekf.counts().reanchored, 1);
}
