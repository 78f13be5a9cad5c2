// The seeded sensors of core/model/sensors.h: encoder quantisation and dead reckoning, the gyro, the position
// fix's rate, latency and dropout, reproducible seeds, refused parameters.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>
#include <vector>

#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/model/robot_params.h"
#include "sowing_robot/core/model/sensors.h"

using namespace sowing_robot::core;

namespace {

SensorParams quiet() {
  SensorParams p;
  p.encoder.noise = 0.0;
  p.imu.noise = 0.0;
  p.imu.bias = 0.0;
  p.fix.sigma = 0.0;
  return p;
}

struct NoSlipRun {
  double max_heading_error = 0.0, max_position_error = 0.0, distance = 0.0;
};

/// The no-slip plant under varying torques for `seconds` at 1 kHz, its wheel angles read by the encoders.
NoSlipRun runNoSlip(const SensorParams& sp, double seconds) {
  const RobotParams robot;
  Plant plant(robot, PlantDisturbance{});
  State x0 = State::Zero();
  x0[X] = -1.0;
  x0[Y] = 0.5;
  x0[THETA] = 0.3;
  plant.reset(x0);
  EncoderOdometry odo(sp, robot.R, robot.L);
  odo.reset({x0[X], x0[Y], x0[THETA]}, x0[PHI_R], x0[PHI_L]);
  NoSlipRun out;
  const double dt = 1e-3;
  const int steps = static_cast<int>(std::lround(seconds / dt));
  for (int k = 0; k < steps; ++k) {
    const double t = k * dt;
    // Speeds up, turns both ways, slows down: forward and backward wheel motion.
    const double tau_r = 1.2 * std::sin(0.7 * t) + 0.4, tau_l = 1.2 * std::sin(0.7 * t + 0.6) + 0.4;
    const State before = plant.state();
    plant.step(tau_r, tau_l, dt);
    const State& s = plant.state();
    out.distance += std::hypot(s[X] - before[X], s[Y] - before[Y]);
    const Odometry2D o = odo.update(s[PHI_R], s[PHI_L], dt);
    out.max_heading_error = std::max(out.max_heading_error, std::fabs(wrapAngle(o.pose.theta - s[THETA])));
    out.max_position_error = std::max(out.max_position_error, std::hypot(o.pose.x - s[X], o.pose.y - s[Y]));
  }
  return out;
}

}  // namespace

TEST(Sensors, DefaultsValidateAndAreTheTypicalValues) {
  const SensorParams p;
  EXPECT_EQ(p.validate(), "");
  EXPECT_EQ(p.encoder.ticks_per_turn, 2048);
  EXPECT_DOUBLE_EQ(p.imu.noise, 0.005);
  EXPECT_DOUBLE_EQ(p.imu.bias, 0.002);
  EXPECT_DOUBLE_EQ(p.fix.rate, 10.0);
  EXPECT_DOUBLE_EQ(p.fix.sigma, 0.02);
  EXPECT_DOUBLE_EQ(p.fix.latency, 0.1);
  EXPECT_DOUBLE_EQ(p.fix.dropout_duration, 0.0);
  // The contract's key names (contract16.md): other code reads them.
  for (const char* key : {"sensors/seed", "sensors/encoder/ticks_per_turn", "sensors/encoder/noise",
                          "sensors/imu/noise", "sensors/imu/bias", "sensors/fix/rate", "sensors/fix/sigma",
                          "sensors/fix/latency", "sensors/fix/dropout_start", "sensors/fix/dropout_duration"})
    EXPECT_NE(sensorsTable().find(key), nullptr) << key;
}

TEST(Sensors, QuantisationErrorIsBelowOneTick) {
  EncoderOdometry odo(quiet(), 0.095, 0.24);
  const double res = odo.resolution();
  EXPECT_DOUBLE_EQ(res, 2.0 * M_PI / 2048);
  double worst = 0.0;
  for (int i = -20000; i <= 20000; ++i) {
    const double phi = 0.000731 * i + 1e-4 * std::sin(i);
    const double err = phi - res * static_cast<double>(odo.read(phi));
    EXPECT_GE(err, -1e-12) << phi;
    EXPECT_LT(err, res) << phi;
    worst = std::max(worst, err);
  }
  EXPECT_GT(worst, 0.9 * res);  // the bound is reached: it is the resolution, not something finer
}

TEST(Sensors, TickJitterIsSeededAndDoesNotAccumulate) {
  SensorParams p = quiet();
  p.encoder.noise = 1.0;
  EncoderOdometry a(p, 0.095, 0.24), b(p, 0.095, 0.24);
  const double res = a.resolution();
  double sum = 0.0, sum2 = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double phi = 100.0 + 0.01 * i;
    const std::int64_t ra = a.read(phi);
    EXPECT_EQ(ra, b.read(phi));
    const double err = (phi - res * static_cast<double>(ra)) / res - 0.5;  // floor's mean offset is half a tick
    sum += err;
    sum2 += err * err;
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.0, 0.05);
  EXPECT_NEAR(var, 1.0 + 1.0 / 12.0, 0.08);  // jitter variance + the uniform quantisation's
}

TEST(Sensors, ZeroNoiseOdometryOfANoSlipRunIsTheTruthToTheQuantisationBound) {
  const RobotParams robot;
  const SensorParams sp = quiet();
  const NoSlipRun run = runNoSlip(sp, 30.0);
  const double travel = robot.R * 2.0 * M_PI / sp.encoder.ticks_per_turn;  // R res
  ASSERT_GT(run.distance, 5.0);
  EXPECT_LE(run.max_heading_error, travel / robot.L + 1e-9);
  EXPECT_LE(run.max_position_error, travel + run.distance * travel / robot.L + 1e-6);
  EXPECT_GT(run.max_heading_error, 0.0);

  // The error is the quantisation's: a finer encoder shrinks it, a coarse one grows it.
  SensorParams fine = sp, coarse = sp;
  fine.encoder.ticks_per_turn = 10000000;
  coarse.encoder.ticks_per_turn = 64;
  const NoSlipRun f = runNoSlip(fine, 30.0), c = runNoSlip(coarse, 30.0);
  EXPECT_LT(f.max_position_error, 1e-4);
  EXPECT_LT(f.max_heading_error, 1e-5);
  EXPECT_GT(c.max_heading_error, 5.0 * run.max_heading_error);
  EXPECT_GT(c.max_position_error, run.max_position_error);
}

TEST(Sensors, WheelsThatTurnMoreThanTheBodyMovesMakeOdometryDrift) {
  // Straight at 1 m/s for 10 s, the wheels spinning 10 % faster than rolling (slip): odometry overshoots.
  const double R = 0.095, L = 0.24, dt = 1e-3;
  EncoderOdometry odo(quiet(), R, L);
  odo.reset({}, 0.0, 0.0);
  Odometry2D o;
  for (int k = 1; k <= 10000; ++k) {
    const double phi = 1.1 * (k * dt) / R;
    o = odo.update(phi, phi, dt);
  }
  EXPECT_NEAR(o.pose.x, 11.0, 2.0 * R * odo.resolution());
  EXPECT_NEAR(o.pose.y, 0.0, 1e-12);
  EXPECT_NEAR(o.v, 1.1, R * odo.resolution() / 0.01 + 1e-9);  // one tick over the 10 ms window
  EXPECT_NEAR(o.omega, 0.0, 1e-12);
}

TEST(Sensors, CovarianceGrowsWithTheDistanceAndStaysSymmetric) {
  const double R = 0.095, L = 0.24, dt = 1e-3;
  SensorParams p = quiet();
  EncoderOdometry odo(p, R, L);
  odo.reset({}, 0.0, 0.0);
  double last_theta = 0.0;
  for (int k = 1; k <= 5000; ++k) {
    const double t = k * dt;
    const Odometry2D o = odo.update((1.0 * t + 0.1 * t * t) / R, (1.0 * t - 0.1 * t * t) / R, dt);
    const Eigen::Matrix3d& P = o.covariance;
    EXPECT_LE((P - P.transpose()).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_GE(P(2, 2), last_theta);  // F keeps theta's row: its variance only grows (x, y's rotate)
    last_theta = P(2, 2);
  }
  const Eigen::Matrix3d P = odo.last().covariance;
  EXPECT_GT(P.eigenvalues().real().minCoeff(), -1e-15);
  EXPECT_GT(P(0, 0) + P(1, 1), 1e-4);  // 5 m along a curve: centimetres of position std
  // theta: two wheels' travel variance k (s_R + s_L) through 1/(2L)², s_R + s_L = 10 m here.
  EXPECT_NEAR(P(2, 2), p.encoder.travel_variance * 10.0 / (4 * L * L), 1e-3 * P(2, 2));
  // At rest nothing grows.
  const double phi_r = (5.0 + 2.5) / R, phi_l = (5.0 - 2.5) / R;
  odo.update(phi_r, phi_l, dt);
  const Eigen::Matrix3d rest = odo.last().covariance;
  odo.update(phi_r, phi_l, dt);
  EXPECT_EQ(odo.last().covariance, rest);
  EXPECT_GT(odo.incrementVariance(), 0.0);
}

TEST(Sensors, YawRateHasItsBiasAndNoise) {
  SensorParams p;
  p.imu.noise = 0.005;
  p.imu.bias = 0.002;
  YawRateSensor gyro(p);
  double sum = 0.0, sum2 = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double e = gyro.measure(0.3) - 0.3;
    sum += e;
    sum2 += e * e;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.002, 4.0 * 0.005 / std::sqrt(n));
  EXPECT_NEAR(sd, 0.005, 0.0002);
  SensorParams q = quiet();
  YawRateSensor exact(q);
  EXPECT_EQ(exact.measure(0.25), 0.25);
}

TEST(Sensors, FixComesAtItsRateStampedLatencyBeforeItsDelivery) {
  SensorParams p = quiet();
  p.fix.rate = 10.0;
  p.fix.latency = 0.1;
  PositionFixSensor fix(p);
  std::vector<std::pair<double, FixMeasurement>> delivered;  // (delivery time, measurement)
  int sampled = 0;
  for (std::int64_t k = 0; k <= 2000; ++k) {
    const double t = secondsFromNanos(k * 1000000);
    if (fix.sample(t, {t, -t, 0.0})) ++sampled;
    for (const FixMeasurement& m : fix.due(t)) delivered.emplace_back(t, m);
  }
  EXPECT_EQ(sampled, 21);            // 0, 0.1, ..., 2.0
  ASSERT_EQ(delivered.size(), 20u);  // the one at 2.0 is still in flight
  for (std::size_t i = 0; i < delivered.size(); ++i) {
    const double stamp = delivered[i].second.stamp;
    EXPECT_NEAR(stamp, 0.1 * i, 1e-9);
    EXPECT_NEAR(delivered[i].first, stamp + 0.1, 1e-9);   // the first step at stamp + latency
    EXPECT_DOUBLE_EQ(delivered[i].second.xy.x(), stamp);  // sigma 0: the truth at the stamp
    EXPECT_DOUBLE_EQ(delivered[i].second.xy.y(), -stamp);
  }
  EXPECT_EQ(fix.pending(), 1u);
}

TEST(Sensors, FixOnACoarseOrOddGridStaysAtItsRate) {
  SensorParams p = quiet();
  p.fix.rate = 7.0;
  p.fix.latency = 0.0;
  PositionFixSensor fix(p);
  std::vector<double> stamps;
  for (std::int64_t k = 0; k < 3000; ++k) {  // 3 s at 1 kHz: samples at the first step at or after n / 7
    const double t = secondsFromNanos(k * 1000000);
    fix.sample(t, {});
    for (const auto& m : fix.due(t)) stamps.push_back(m.stamp);
  }
  ASSERT_EQ(stamps.size(), 21u);
  for (std::size_t n = 0; n < stamps.size(); ++n) {
    EXPECT_GE(stamps[n], n / 7.0 - 1e-9);
    EXPECT_LT(stamps[n], n / 7.0 + 1e-3);
  }
}

TEST(Sensors, FixDropoutLosesExactlyItsWindowAndNotTheOthersNoise) {
  SensorParams p;
  p.fix.dropout_start = 0.5;
  p.fix.dropout_duration = 0.3;
  SensorParams none = p;
  none.fix.dropout_duration = 0.0;
  PositionFixSensor with(p), without(none);
  std::vector<FixMeasurement> a, b;
  for (std::int64_t k = 0; k <= 1500; ++k) {
    const double t = secondsFromNanos(k * 1000000);
    with.sample(t, {1.0, 2.0, 0.0});
    without.sample(t, {1.0, 2.0, 0.0});
    for (const auto& m : with.due(t)) a.push_back(m);
    for (const auto& m : without.due(t)) b.push_back(m);
  }
  ASSERT_EQ(b.size(), 15u);  // 0 .. 1.4
  ASSERT_EQ(a.size(), 12u);  // without 0.5, 0.6, 0.7
  std::size_t j = 0;
  for (const auto& m : b) {
    if (m.stamp > 0.5 - 1e-9 && m.stamp < 0.8 - 1e-9) continue;
    ASSERT_LT(j, a.size());
    EXPECT_EQ(a[j].stamp, m.stamp);
    EXPECT_EQ(a[j].xy, m.xy);  // same noise draws outside the window
    ++j;
  }
  EXPECT_EQ(j, a.size());
  EXPECT_TRUE(with.inDropout(0.5));
  EXPECT_TRUE(with.inDropout(0.79));
  EXPECT_FALSE(with.inDropout(0.8));
  EXPECT_FALSE(with.inDropout(0.49));
}

TEST(Sensors, FixNoiseHasItsSigma) {
  SensorParams p;
  p.fix.sigma = 0.02;
  p.fix.rate = 1000.0;
  p.fix.latency = 0.0;
  PositionFixSensor fix(p);
  double sum2 = 0.0;
  int n = 0;
  for (std::int64_t k = 0; k < 50000; ++k) {
    const double t = secondsFromNanos(k * 1000000);
    fix.sample(t, {3.0, 4.0, 0.0});
    for (const auto& m : fix.due(t)) {
      sum2 += (m.xy - Eigen::Vector2d(3.0, 4.0)).squaredNorm();
      n += 2;
      EXPECT_EQ(m.sigma, 0.02);
    }
  }
  ASSERT_EQ(n, 100000);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.02, 0.0005);
}

TEST(Sensors, SeedsReproduceAndDiffer) {
  SensorParams p;
  p.encoder.noise = 0.5;
  SensorParams other = p;
  other.seed = p.seed + 1;
  auto trace = [](const SensorParams& sp) {
    std::vector<double> out;
    EncoderOdometry odo(sp, 0.095, 0.24);
    YawRateSensor gyro(sp);
    PositionFixSensor fix(sp);
    for (int k = 1; k <= 1000; ++k) {
      const double t = 1e-3 * k;
      const Odometry2D o = odo.update(t / 0.095, 0.9 * t / 0.095, 1e-3);
      out.push_back(o.pose.x);
      out.push_back(o.pose.theta);
      out.push_back(gyro.measure(0.1));
      fix.sample(t, {t, 0.0, 0.0});
      for (const auto& m : fix.due(t)) out.push_back(m.xy.x());
    }
    return out;
  };
  const std::vector<double> a = trace(p), b = trace(p), c = trace(other);
  EXPECT_EQ(a, b);
  ASSERT_EQ(a.size(), c.size());
  EXPECT_NE(a, c);
  // reset() re-seeds: the same draws again.
  YawRateSensor g(p);
  const double first = g.measure(0.0);
  g.measure(0.0);
  g.reset();
  EXPECT_EQ(g.measure(0.0), first);
  // Each sensor has its own stream: the gyro's draws do not depend on the encoder's noise.
  SensorParams jitter = p;
  jitter.encoder.noise = 2.0;
  YawRateSensor g1(p), g2(jitter);
  EXPECT_EQ(g1.measure(0.0), g2.measure(0.0));
}

TEST(Sensors, BadParametersAreRefusedNamingTheKey) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    const char* key;
    void (*spoil)(SensorParams&);
  };
  const Case cases[] = {
      {"sensors/encoder/ticks_per_turn", [](SensorParams& p) { p.encoder.ticks_per_turn = 0; }},
      {"sensors/encoder/noise", [](SensorParams& p) { p.encoder.noise = -0.1; }},
      {"sensors/encoder/travel_variance", [](SensorParams& p) { p.encoder.travel_variance = -1e-6; }},
      {"sensors/encoder/velocity_window", [](SensorParams& p) { p.encoder.velocity_window = -0.01; }},
      {"sensors/imu/noise", [](SensorParams& p) { p.imu.noise = -0.005; }},
      {"sensors/imu/bias", [](SensorParams& p) { p.imu.bias = std::numeric_limits<double>::quiet_NaN(); }},
      {"sensors/fix/rate", [](SensorParams& p) { p.fix.rate = 0.0; }},
      {"sensors/fix/rate", [](SensorParams& p) { p.fix.rate = std::numeric_limits<double>::quiet_NaN(); }},
      {"sensors/fix/sigma", [](SensorParams& p) { p.fix.sigma = -0.02; }},
      {"sensors/fix/latency", [](SensorParams& p) { p.fix.latency = std::numeric_limits<double>::infinity(); }},
      {"sensors/fix/dropout_start", [](SensorParams& p) { p.fix.dropout_start = -1.0; }},
      {"sensors/fix/dropout_duration", [](SensorParams& p) { p.fix.dropout_duration = -1.0; }},
  };
  for (const Case& c : cases) {
    SensorParams p;
    c.spoil(p);
    const std::string e = p.validate();
    EXPECT_NE(e.find(c.key), std::string::npos) << c.key << ": " << e;
    EXPECT_THROW(EncoderOdometry(p, 0.095, 0.24), std::invalid_argument) << c.key;
    EXPECT_THROW(YawRateSensor{p}, std::invalid_argument) << c.key;
    EXPECT_THROW(PositionFixSensor{p}, std::invalid_argument) << c.key;
  }
  EXPECT_THROW(EncoderOdometry(SensorParams{}, nan, 0.24), std::invalid_argument);
  EXPECT_THROW(EncoderOdometry(SensorParams{}, 0.095, -0.24), std::invalid_argument);
  EncoderOdometry odo(SensorParams{}, 0.095, 0.24);
  EXPECT_THROW(odo.update(nan, 0.0, 1e-3), std::invalid_argument);
  EXPECT_THROW(odo.update(0.0, 0.0, 0.0), std::invalid_argument);
}
