#include "sowing_robot/core/model/sensors.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {
namespace {

constexpr double kTimeTolerance = 1e-9;  // [s] stamps on the control grid carry rounding of this order

const ParamTable<EncoderParams>& encoderTable() {
  using E = EncoderParams;
  static const ParamTable<E> table({
      integer("ticks_per_turn", &E::ticks_per_turn, 2048, Limits::closed(1.0, 1e7), "",
              "encoder counts per wheel revolution (quantisation of the wheel angle: 2π / this)"),
      number("noise", &E::noise, 0.0, Limits::closed(0.0, 100.0), "",
             "std of each reading's tick jitter, in ticks (does not accumulate); 0 = quantisation only"),
      number("travel_variance", &E::travel_variance, 1e-4, Limits::closed(0.0, 1.0), "m²/m",
             "odom covariance only: each wheel's travel variance grows by this per metre travelled"),
      number("velocity_window", &E::velocity_window, 0.01, Limits::closed(0.0, 1.0), "s",
             "odom twist = count increments over this long (0 = the last step's increment alone)"),
  });
  return table;
}

const ParamTable<ImuParams>& imuTable() {
  using I = ImuParams;
  static const ParamTable<I> table({
      number("noise", &I::noise, 0.005, Limits::closed(0.0, 10.0), "rad/s", "std of the gyro's yaw-rate noise"),
      number("bias", &I::bias, 0.002, Limits::closed(-1.0, 1.0), "rad/s", "constant gyro yaw-rate bias (either sign)"),
  });
  return table;
}

const ParamTable<FixParams>& fixTable() {
  using F = FixParams;
  static const ParamTable<F> table({
      number("rate", &F::rate, 10.0, Limits::above(0.0, 1000.0), "Hz", "position fix rate"),
      number("sigma", &F::sigma, 0.02, Limits::closed(0.0, 100.0), "m", "std of the fix's x and y"),
      number("latency", &F::latency, 0.1, Limits::closed(0.0, 10.0), "s",
             "a fix is published this long after its measurement time (its header stamp)"),
      number("dropout_start", &F::dropout_start, 0.0, Limits::closed(0.0, 1e7), "s",
             "sim time a fix dropout begins (no fix measured in it)"),
      number("dropout_duration", &F::dropout_duration, 0.0, Limits::closed(0.0, 1e7), "s",
             "length of the fix dropout; 0 = none"),
  });
  return table;
}

}  // namespace

const ParamTable<SensorParams>& sensorsTable() {
  using S = SensorParams;
  static const ParamTable<S> table = [] {
    ParamTable<S> t({
        integer("sensors/seed", &S::seed, 1, Limits::closed(0.0, 2147483647.0), "",
                "base seed of the sensors' noise (each sensor adds its own offset)"),
    });
    t.nest("sensors/encoder/", &S::encoder, encoderTable());
    t.nest("sensors/imu/", &S::imu, imuTable());
    return t.nest("sensors/fix/", &S::fix, fixTable());
  }();
  return table;
}

SensorParams::SensorParams() { sensorsTable().applyDefaults(*this); }

std::string SensorParams::validate() const { return sensorsTable().checkRanges(*this); }

std::mt19937_64 sensorGenerator(std::uint64_t seed, std::uint64_t offset) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(offset), static_cast<std::uint32_t>(offset >> 32)};
  return std::mt19937_64(seq);
}

namespace {
void requireValid(const SensorParams& p) {
  const std::string e = p.validate();
  if (!e.empty()) throw std::invalid_argument(e);
}
}  // namespace

// --- EncoderOdometry -------------------------------------------------------------------------------

EncoderOdometry::EncoderOdometry(const SensorParams& params, double R, double L) : params_(params), R_(R), L_(L) {
  requireValid(params);
  if (!(std::isfinite(R) && R > 0.0) || !(std::isfinite(L) && L > 0.0))
    throw std::invalid_argument("encoder odometry: wheel radius and half track must be finite and > 0 (R = " +
                                formatNumber(R) + ", L = " + formatNumber(L) + ")");
  resolution_ = 2.0 * M_PI / params.encoder.ticks_per_turn;
  const double travel = R_ * resolution_, n = params.encoder.noise;
  q0_ = travel * travel * (1.0 / 6.0 + 2.0 * n * n);
  reset(Pose2D{}, 0.0, 0.0);
}

std::int64_t EncoderOdometry::read(double phi) {
  double ticks = phi / resolution_;
  if (params_.encoder.noise > 0.0) ticks += params_.encoder.noise * normal_(rng_);
  return static_cast<std::int64_t>(std::floor(ticks));
}

void EncoderOdometry::reset(const Pose2D& pose, double phi_r, double phi_l) {
  if (!allFinite(pose.x, pose.y, pose.theta, phi_r, phi_l))
    throw std::invalid_argument("encoder odometry reset: non-finite pose or wheel angle");
  rng_ = sensorGenerator(params_.seed, kEncoderSeedOffset);
  normal_.reset();
  count_r_ = read(phi_r);
  count_l_ = read(phi_l);
  window_.clear();
  if (window_.full()) window_.set_capacity(16);
  window_.push_back({count_r_, count_l_, 0.0});
  window_time_ = 0.0;
  out_ = Odometry2D{};
  out_.pose = pose;
}

Odometry2D EncoderOdometry::update(double phi_r, double phi_l, double dt) {
  if (!allFinite(phi_r, phi_l, dt) || !(dt > 0.0))
    throw std::invalid_argument("encoder odometry update: non-finite wheel angle or dt <= 0");
  const std::int64_t r = read(phi_r), l = read(phi_l);
  const double ds_r = R_ * resolution_ * static_cast<double>(r - count_r_);
  const double ds_l = R_ * resolution_ * static_cast<double>(l - count_l_);
  count_r_ = r;
  count_l_ = l;

  const double ds = 0.5 * (ds_r + ds_l), b = 2.0 * L_, dth = (ds_r - ds_l) / b;
  Pose2D& p = out_.pose;
  const double mid = p.theta + 0.5 * dth;
  double s, c;
  s = std::sin(mid);
  c = std::cos(mid);
  // Jacobians at the pose before the update: F in (x, y, theta), G in (Δs_R, Δs_L).
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 2) = -ds * s;
  F(1, 2) = ds * c;
  Eigen::Matrix<double, 3, 2> G;
  const double k = ds / (2.0 * b);
  G << 0.5 * c - k * s, 0.5 * c + k * s, 0.5 * s + k * c, 0.5 * s - k * c, 1.0 / b, -1.0 / b;
  const double kt = params_.encoder.travel_variance;
  const Eigen::Vector2d q(kt * std::fabs(ds_r), kt * std::fabs(ds_l));
  out_.covariance = F * out_.covariance * F.transpose() + G * q.asDiagonal() * G.transpose();
  p.x += ds * c;
  p.y += ds * s;
  p.theta = wrapAngle(p.theta + dth);

  // Velocities over the window: keep the oldest reading at least velocity_window before this one.
  if (window_.full()) window_.set_capacity(std::max<std::size_t>(16, 2 * window_.capacity()));
  window_.push_back({r, l, dt});
  window_time_ += dt;
  while (window_.size() > 2 && window_time_ - window_[1].dt >= params_.encoder.velocity_window - kTimeTolerance) {
    window_time_ -= window_[1].dt;
    window_.pop_front();
  }
  const double span = window_time_, travel = R_ * resolution_;
  const double wr = travel * static_cast<double>(r - window_.front().r);
  const double wl = travel * static_cast<double>(l - window_.front().l);
  out_.v = 0.5 * (wr + wl) / span;
  out_.omega = (wr - wl) / (b * span);
  out_.delta_s = ds;
  out_.delta_theta = dth;
  out_.delta_right = ds_r;
  out_.delta_left = ds_l;
  return out_;
}

// --- YawRateSensor ---------------------------------------------------------------------------------

YawRateSensor::YawRateSensor(const SensorParams& params) : params_(params) {
  requireValid(params);
  reset();
}

void YawRateSensor::reset() {
  rng_ = sensorGenerator(params_.seed, kImuSeedOffset);
  normal_.reset();
}

double YawRateSensor::measure(double omega_true) {
  double z = omega_true + params_.imu.bias;
  if (params_.imu.noise > 0.0) z += params_.imu.noise * normal_(rng_);
  return z;
}

// --- PositionFixSensor -----------------------------------------------------------------------------

void FixSchedule::reset(double t0) {
  t0_ = t0;
  next_ = 0;
}

bool FixSchedule::inDropout(double stamp) const {
  return params_.dropout_duration > 0.0 && stamp >= params_.dropout_start - kTimeTolerance &&
         stamp < params_.dropout_start + params_.dropout_duration - kTimeTolerance;
}

bool FixSchedule::sample(double t) {
  const double due_at = t0_ + static_cast<double>(next_) / params_.rate;
  if (t < due_at - kTimeTolerance) return false;
  // Catch up past slots a coarse caller skipped (t is the first call at or after each one's time): one
  // measurement per call, the rest of the skipped slots are gone.
  next_ = static_cast<std::int64_t>(std::floor((t - t0_) * params_.rate + kTimeTolerance)) + 1;
  return true;
}

PositionFixSensor::PositionFixSensor(const SensorParams& params) : params_(params), schedule_(params.fix) {
  requireValid(params);
  reset(0.0);
}

void PositionFixSensor::reset(double t0) {
  if (!std::isfinite(t0)) throw std::invalid_argument("position fix reset: non-finite time");
  rng_ = sensorGenerator(params_.seed, kFixSeedOffset);
  normal_.reset();
  schedule_.reset(t0);
  pending_.clear();
}

bool PositionFixSensor::sample(double t, const Pose2D& truth) {
  if (!schedule_.sample(t)) return false;
  FixMeasurement m;
  m.stamp = t;
  m.sigma = params_.fix.sigma;
  const double nx = normal_(rng_), ny = normal_(rng_);  // drawn even in a dropout: see the header
  m.xy = Eigen::Vector2d(truth.x + params_.fix.sigma * nx, truth.y + params_.fix.sigma * ny);
  if (!inDropout(t)) pending_.push_back(m);
  return true;
}

const std::vector<FixMeasurement>& PositionFixSensor::due(double t) {
  due_.clear();  // its storage kept
  while (!pending_.empty() && pending_.front().stamp + params_.fix.latency <= t + kTimeTolerance) {
    due_.push_back(pending_.front());
    pending_.pop_front();
  }
  return due_;
}

}  // namespace core
}  // namespace sowing_robot
