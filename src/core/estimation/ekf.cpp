#include "sowing_robot/core/estimation/ekf.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sowing_robot {
namespace core {
namespace {

constexpr double kStampTolerance = 1e-6;  // [s] fixes are sampled on plant steps (1 ms apart at 1 kHz)
// A wheel found loose by the averaged tests is taken as loose from this many slip/window before (the
// averages' delay in finding a spin-up).
constexpr double kSlipLookback = 4.0;

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

bool finiteMatrix(const Eigen::MatrixXd& m) { return m.allFinite(); }

}  // namespace

const ParamTable<EkfParams>& ekfTable() {
  using P = EkfParams;
  static const ParamTable<P> table({
      number("estimator/odometry/distance_noise", &P::distance_noise, 0.01, Limits::closed(0.0, 10.0), "m/√m",
             "encoder distance error per square root of the distance rolled (slip, wheel radius), added to the "
             "odometry's own covariance"),
      number("estimator/odometry/heading_noise", &P::heading_noise, 0.03, Limits::closed(0.0, 10.0), "rad/√m",
             "encoder heading error per square root of the distance rolled (uneven slip, track width)"),
      number("estimator/odometry/increment_sigma", &P::increment_sigma, 1.19e-4, Limits::closed(0.0, 1.0), "m",
             "std of one wheel-travel increment from the encoders' quantisation, as the filter believes it "
             "(2048 ticks per turn on R = 0.095 m: R 2π/2048/√6 = 1.19e-4)"),
      number("estimator/bias/walk", &P::bias_walk, 1e-4, Limits::closed(0.0, 1.0), "rad/s/√s",
             "random walk of the yaw-rate sensor's bias"),
      flag("estimator/bias/estimate", &P::estimate_bias, true,
           "the yaw-rate bias is a state of the filter; false: taken as 0"),
      number("estimator/initial/sigma_xy", &P::initial_sigma_xy, 0.05, Limits::closed(0.0, 100.0), "m",
             "initial standard deviation of x and y"),
      number("estimator/initial/sigma_theta", &P::initial_sigma_theta, 0.02, Limits::closed(0.0, 10.0), "rad",
             "initial standard deviation of the heading"),
      number("estimator/initial/sigma_bias", &P::initial_sigma_bias, 0.01, Limits::closed(0.0, 10.0), "rad/s",
             "initial standard deviation of the yaw-rate bias"),
      integer("estimator/history/length", &P::history_length, 1000, Limits::closed(2.0, 1000000.0), "",
              "plant steps of states and inputs kept, so that a fix up to this old is applied at its stamp"),
      number("estimator/fix/gate", &P::gate, 25.0, Limits::closed(0.0, 1e12), "",
             "squared Mahalanobis distance of a fix's innovation above which it is refused (chi-square, 2 dof: "
             "13.8 = 0.1 %); 0: no gate"),
      integer("estimator/fix/reanchor_after", &P::reanchor_after, 5, Limits::closed(0.0, 1000000.0), "",
              "gated fixes in a row after which the next gated fix is taken as the position (x, y and their "
              "covariance from it; heading and bias kept): the way back after wheel slip; 0: never"),
      number("estimator/slip/inflation", &P::slip_inflation, 100.0, Limits::closed(1.0, 1e6), "",
             "after a fix outside the gate (wheel slip), the distance noise's variance times this until an applied "
             "fix agrees with the prediction within the fix's own noise; 1: off (the filter without slip/detect)"),
      number("estimator/fix/delay", &P::fix_delay, 0.15, Limits::closed(0.0, 100.0), "s",
             "a fix is applied once the estimate is this much newer than its stamp, so runs are repeatable; >= "
             "the fix's latency plus two control periods, and within history/length"),
  });
  static const ParamTable<P> with_slip = [] {
    ParamTable<P> t = table;
    t.nest("estimator/slip/", &P::slip, slipParamsTable());
    return t;
  }();
  return with_slip;
}

EkfParams::EkfParams() { ekfTable().applyDefaults(*this); }

std::string EkfParams::validate() const { return ekfTable().checkRanges(*this); }

const char* fixOutcomeName(FixOutcome o) {
  switch (o) {
    case FixOutcome::APPLIED: return "applied";
    case FixOutcome::REANCHORED: return "re-anchored";
    case FixOutcome::REFUSED_INVALID: return "invalid";
    case FixOutcome::REFUSED_TOO_OLD: return "older than the history";
    case FixOutcome::REFUSED_FUTURE: return "newer than the estimate";
    case FixOutcome::REFUSED_GATE: return "outside the gate";
  }
  return "?";
}

Ekf::Ekf(const EkfParams& params, double half_track) : params_(params), half_track_(half_track) {
  const std::string error = params.validate();
  if (!error.empty()) throw std::invalid_argument(error);
  history_.set_capacity(static_cast<std::size_t>(params.history_length));
  if (params.slip.detect) detector_.emplace(params.slip, half_track);  // throws for a bad half track
}

void Ekf::pinBias(Vector& mean, Matrix& cov) const {
  if (params_.estimate_bias) return;
  mean(BIAS) = 0.0;
  cov.row(BIAS).setZero();
  cov.col(BIAS).setZero();
}

void Ekf::reset(double t, const Pose2D& pose, double bias) {
  Vector m;
  m << pose.x, pose.y, wrapAngle(pose.theta), bias;
  Matrix c = Matrix::Zero();
  c(X, X) = c(Y, Y) = params_.initial_sigma_xy * params_.initial_sigma_xy;
  c(THETA, THETA) = params_.initial_sigma_theta * params_.initial_sigma_theta;
  c(BIAS, BIAS) = params_.initial_sigma_bias * params_.initial_sigma_bias;
  reset(t, m, c);
}

void Ekf::reset(double t, const Vector& mean, const Matrix& covariance) {
  if (!std::isfinite(t) || !mean.allFinite() || !covariance.allFinite())
    throw std::invalid_argument("Ekf::reset: non-finite time, mean or covariance");
  if ((covariance - covariance.transpose()).cwiseAbs().maxCoeff() >
      1e-12 * std::max(1.0, covariance.cwiseAbs().maxCoeff()))
    throw std::invalid_argument("Ekf::reset: covariance is not symmetric");
  Entry e{t, mean, covariance, EkfStepInput{}, {}};
  e.mean(THETA) = wrapAngle(e.mean(THETA));
  pinBias(e.mean, e.cov);
  if (detector_) {  // at rest (half the top speed's std), the wheels gripping (slip/speed_tolerance's std)
    e.smean.head<4>() = e.mean;
    e.scov.topLeftCorner<4, 4>() = e.cov;
    const double speed = 0.5 * params_.slip.max_ground_speed, slip = params_.slip.speed_tolerance;
    e.scov(kSpeed, kSpeed) = speed * speed;
    e.scov(kSlipRight, kSlipRight) = e.scov(kSlipLeft, kSlipLeft) = slip * slip;
    detector_->reset();
  }
  history_.clear();
  history_.push_back(std::move(e));
  slipping_ = false;
  pending_inflation_.setZero();
}

Ekf::Vector Ekf::motion(const Vector6& a) {
  const double mid = a(THETA) + 0.5 * a(4), u = a(5);
  Vector s;
  double sn, c;
  sn = std::sin(mid);
  c = std::cos(mid);
  s << a(X) + u * c, a(Y) + u * sn, wrapAngle(a(THETA) + a(4)), a(BIAS);
  return s;
}

Eigen::Matrix<double, 4, 6> Ekf::motionJacobian(const Vector6& a) {
  const double mid = a(THETA) + 0.5 * a(4), u = a(5);
  double s, c;
  s = std::sin(mid);
  c = std::cos(mid);
  Eigen::Matrix<double, 4, 6> f = Eigen::Matrix<double, 4, 6>::Zero();
  f(X, X) = 1.0;
  f(X, THETA) = -u * s;
  f(X, 4) = -0.5 * u * s;
  f(X, 5) = c;
  f(Y, Y) = 1.0;
  f(Y, THETA) = u * c;
  f(Y, 4) = 0.5 * u * c;
  f(Y, 5) = s;
  f(THETA, THETA) = 1.0;
  f(THETA, 4) = 1.0;
  f(BIAS, BIAS) = 1.0;
  return f;
}

void Ekf::propagate(const EkfParams& p, double dt, const EkfStepInput& in, Vector& mean, Matrix& cov) {
  // Augmented prior: the state and the step's (d, u) from the encoders, independent of it.
  Vector6 a;
  a << mean, in.dtheta, in.distance;
  Matrix6 pa = Matrix6::Zero();
  pa.topLeftCorner<4, 4>() = cov;
  const double rolled = std::fabs(in.distance);
  pa(4, 4) = in.covariance(1, 1) + p.heading_noise * p.heading_noise * rolled;
  pa(5, 5) = in.covariance(0, 0) + p.distance_noise * p.distance_noise * rolled;
  pa(4, 5) = pa(5, 4) = in.covariance(0, 1);
  if (in.has_rate) {
    // r dt = d + b dt + noise: linear in a, so this update is exact.
    Vector6 h = Vector6::Zero();
    h(4) = 1.0;
    h(BIAS) = dt;
    const double r = in.rate_variance * dt * dt;
    const Vector6 ph = pa * h;
    const double s = h.dot(ph) + r;
    if (s > 0.0) {
      const Vector6 k = ph / s;
      a += k * (in.rate * dt - h.dot(a));
      const Matrix6 ikh = Matrix6::Identity() - k * h.transpose();
      pa = ikh * pa * ikh.transpose() + (k * r) * k.transpose();
    }
  }
  const Eigen::Matrix<double, 4, 6> f = motionJacobian(a);
  mean = motion(a);
  cov = f * pa * f.transpose();
  if (p.estimate_bias) cov(BIAS, BIAS) += p.bias_walk * p.bias_walk * dt;
  cov = 0.5 * (cov + cov.transpose());
}

double Ekf::update(const EkfFix& fix, Vector& mean, Matrix& cov, bool apply) {
  const Eigen::Vector2d nu = fix.xy - mean.head<2>();
  const Eigen::Matrix2d s = cov.topLeftCorner<2, 2>() + fix.covariance;
  const Eigen::Matrix2d s_inv = s.inverse();
  const double d2 = nu.dot(s_inv * nu);
  if (!apply) return d2;
  const Eigen::Matrix<double, 4, 2> k = cov.leftCols<2>() * s_inv;  // P H^T S^-1, H = [I 0]
  mean += k * nu;
  mean(THETA) = wrapAngle(mean(THETA));
  Matrix ikh = Matrix::Identity();
  ikh.leftCols<2>() -= k;
  cov = ikh * cov * ikh.transpose() + k * fix.covariance * k.transpose();
  cov = 0.5 * (cov + cov.transpose());
  return d2;
}

void Ekf::reanchor(const EkfFix& fix, Vector& mean, Matrix& cov) {
  mean.head<2>() = fix.xy;
  cov.topRows<2>().setZero();
  cov.leftCols<2>().setZero();
  cov.topLeftCorner<2, 2>() = fix.covariance;
}

void Ekf::append(const Entry& e) {
  if (!history_.full()) {
    history_.push_back(e);
    return;
  }
  // The oldest entry becomes the newest (constant time on a full ring) and is overwritten: its fixes' vector
  // keeps its storage, so a step allocates nothing.
  history_.rotate(history_.begin() + 1);
  history_.back() = e;
}

bool Ekf::predict(double t, const EkfStepInput& in) {
  if (history_.empty() || !std::isfinite(t) || !(t > time())) return false;
  if (!allFinite(in.distance, in.dtheta, in.rate, in.rate_variance) || !finiteMatrix(in.covariance)) return false;
  if (in.covariance(0, 0) < 0.0 || in.covariance(1, 1) < 0.0 || in.rate_variance < 0.0) return false;
  if (detector_) return predictSlipAware(t, in);
  Entry e{t, mean(), covariance(), in, {}};
  if (slipping_)  // kept in the entry's input: a re-propagation meets the same inflation
    e.input.covariance(0, 0) +=
        (params_.slip_inflation - 1.0) * params_.distance_noise * params_.distance_noise * std::fabs(in.distance);
  propagate(params_, t - time(), e.input, e.mean, e.cov);
  pinBias(e.mean, e.cov);
  if (!e.mean.allFinite() || !e.cov.allFinite()) return false;
  append(e);
  return true;
}

FixOutcome Ekf::fuse(const EkfFix& fix) {
  const auto refuse = [](long& count, FixOutcome o) {
    ++count;
    return o;
  };
  if (history_.empty() || !std::isfinite(fix.stamp) || !fix.xy.allFinite() || !fix.covariance.allFinite() ||
      fix.covariance(0, 1) != fix.covariance(1, 0) || fix.covariance.llt().info() != Eigen::Success)
    return refuse(counts_.invalid, FixOutcome::REFUSED_INVALID);
  if (fix.stamp < history_.front().t - kStampTolerance) return refuse(counts_.too_old, FixOutcome::REFUSED_TOO_OLD);
  if (fix.stamp > history_.back().t + kStampTolerance) return refuse(counts_.future, FixOutcome::REFUSED_FUTURE);
  // The newest kept state not after the stamp.
  std::size_t k = history_.size() - 1;
  while (k > 0 && history_[k].t > fix.stamp + kStampTolerance) --k;
  if (detector_) return fuseSlipAware(fix, k);
  Entry& at = history_[k];
  bool anchor = false;
  if (params_.gate > 0.0 && update(fix, at.mean, at.cov, false) > params_.gate) {
    if (params_.slip_inflation > 1.0 && !slipping_) {
      slipping_ = true;
      ++counts_.slip_onsets;
    }
    if (params_.reanchor_after <= 0 || gated_in_a_row_ < params_.reanchor_after) {
      ++gated_in_a_row_;
      return refuse(counts_.gated, FixOutcome::REFUSED_GATE);
    }
    anchor = true;
  } else if (slipping_) {
    // The wheels grip again when the fix agrees with the prediction within its own noise: the inflated
    // covariance would let every applied fix look like agreement.
    const Eigen::Vector2d nu = fix.xy - at.mean.head<2>();
    if (nu.dot(fix.covariance.ldlt().solve(nu)) < 1.0) slipping_ = false;
  }
  gated_in_a_row_ = 0;
  if (anchor)
    reanchor(fix, at.mean, at.cov);
  else
    update(fix, at.mean, at.cov);
  pinBias(at.mean, at.cov);
  at.fixes.push_back({fix, anchor});
  // Propagate again from there, with the kept inputs and the fixes already applied later on (in the
  // order a filter applying each at its stamp would have met them; accepted then, not gated again).
  for (std::size_t i = k + 1; i < history_.size(); ++i) {
    Entry& e = history_[i];
    e.mean = history_[i - 1].mean;
    e.cov = history_[i - 1].cov;
    propagate(params_, e.t - history_[i - 1].t, e.input, e.mean, e.cov);
    pinBias(e.mean, e.cov);
    for (const Entry::Applied& f : e.fixes) {
      if (f.reanchor)
        reanchor(f.fix, e.mean, e.cov);
      else
        update(f.fix, e.mean, e.cov);
    }
    pinBias(e.mean, e.cov);
  }
  ++counts_.applied;
  if (!anchor) return FixOutcome::APPLIED;
  ++counts_.reanchored;
  return FixOutcome::REANCHORED;
}

void Ekf::settle(Entry& e) const {
  if (!params_.estimate_bias) {
    e.smean(BIAS) = 0.0;
    e.scov.row(BIAS).setZero();
    e.scov.col(BIAS).setZero();
  }
  e.mean = e.smean.head<4>();
  e.cov = e.scov.topLeftCorner<4, 4>();
}

unsigned Ekf::slippingAt(const Entry& e) const {
  unsigned out = e.loose;
  if (std::fabs(e.smean(kSlipRight)) > params_.slip.speed_tolerance) out |= SLIP_RIGHT;
  if (std::fabs(e.smean(kSlipLeft)) > params_.slip.speed_tolerance) out |= SLIP_LEFT;
  return out;
}

void Ekf::stepSlipAware(const Entry& before, Entry& e) const {
  e.smean = before.smean;
  e.scov = before.scov;
  for (int i = 0; i < 3; ++i) e.scov(kSpeed + i, kSpeed + i) += e.inflation(i);
  slipAwarePropagate(params_, half_track_, e.t - before.t, e.input, e.loose, e.smean, e.scov);
  settle(e);
}

bool Ekf::predictSlipAware(double t, const EkfStepInput& in) {
  const Entry& last = history_.back();
  const double dt = t - last.t, L = half_track_;
  SlipEvidence ev;
  ev.dt = dt;
  ev.travel_right = in.distance + L * in.dtheta;
  ev.travel_left = in.distance - L * in.dtheta;
  ev.has_rate = in.has_rate;
  ev.rate = in.rate - last.smean(BIAS);
  unsigned onset = SLIP_NONE;
  Entry e{t, last.mean, last.cov, in, {}};
  e.loose = detector_->step(ev, onset);
  e.inflation = pending_inflation_;
  pending_inflation_.setZero();
  // A wheel plausible again: its slip is whatever it is now (spinning on at a new speed, or gripping);
  // its variance is opened, and the next steps take it from the other wheel, the gyro and the fixes.
  const unsigned regained = last.loose & ~e.loose;
  const double open = params_.slip.max_ground_speed * params_.slip.max_ground_speed;
  if (regained & SLIP_RIGHT) e.inflation(1) += open;
  if (regained & SLIP_LEFT) e.inflation(2) += open;
  stepSlipAware(last, e);
  if (!e.smean.allFinite() || !e.scov.allFinite()) return false;
  append(e);
  if (onset != SLIP_NONE) {
    // Found with the averages' delay: the wheel broke loose kSlipLookback windows before.
    std::size_t k = history_.size() - 1;
    while (k > 0 && history_[k].t > t - kSlipLookback * params_.slip.window + kStampTolerance) --k;
    markLoose(k, onset);
    repropagateSlipAware(k);
  }
  if (slippingAt(history_.back()) != SLIP_NONE) detector_->countSlipping(dt);
  return true;
}

void Ekf::markLoose(std::size_t k, unsigned wheels) {
  for (std::size_t i = k + 1; i < history_.size(); ++i) history_[i].loose |= wheels;
}

void Ekf::reacquire(std::size_t k, unsigned wheels, double open) {
  Eigen::Vector3d& inflation = k + 1 < history_.size() ? history_[k + 1].inflation : pending_inflation_;
  if (wheels & SLIP_RIGHT) inflation(1) += open;
  if (wheels & SLIP_LEFT) inflation(2) += open;
}

void Ekf::repropagateSlipAware(std::size_t k) {
  for (std::size_t i = k + 1; i < history_.size(); ++i) {
    Entry& e = history_[i];
    stepSlipAware(history_[i - 1], e);
    for (const Entry::Applied& f : e.fixes) {
      if (f.reanchor)
        slipAwareReanchor(f.fix, e.smean, e.scov);
      else
        slipAwareUpdate(f.fix, e.smean, e.scov, true, nullptr, slippingAt(e) == SLIP_BOTH);
      settle(e);
    }
  }
}

FixOutcome Ekf::fuseSlipAware(const EkfFix& fix, std::size_t k) {
  Entry& at = history_[k];
  double along = 0.0;
  const double d2 = slipAwareUpdate(fix, at.smean, at.scov, false, &along);
  bool anchor = false;
  if (params_.gate > 0.0 && d2 > params_.gate) {
    // Outside the gate: the wheels' slips are not what the filter thinks (both, from the fix's stamp on).
    detector_->gatedFix();
    reacquire(k, SLIP_BOTH, params_.slip.max_ground_speed * params_.slip.max_ground_speed);
    repropagateSlipAware(k);
    if (params_.reanchor_after <= 0 || gated_in_a_row_ < params_.reanchor_after) {
      ++gated_in_a_row_;
      ++counts_.gated;
      return FixOutcome::REFUSED_GATE;
    }
    anchor = true;
  } else if (const double evidence = detector_->fix(fix.stamp, along)) {
    // The CUSUM's alarm: the slips may have drifted unseen as far as the speed's random walk allows.
    reacquire(k, SLIP_BOTH,
              std::min(params_.slip.speed_walk * params_.slip.speed_walk * evidence,
                       params_.slip.max_ground_speed * params_.slip.max_ground_speed));
  }
  gated_in_a_row_ = 0;
  const bool keep_heading = slippingAt(at) == SLIP_BOTH;
  if (anchor)
    slipAwareReanchor(fix, at.smean, at.scov);
  else
    slipAwareUpdate(fix, at.smean, at.scov, true, nullptr, keep_heading);
  settle(at);
  at.fixes.push_back({fix, anchor});
  repropagateSlipAware(k);
  ++counts_.applied;
  if (!anchor) return FixOutcome::APPLIED;
  ++counts_.reanchored;
  return FixOutcome::REANCHORED;
}

Eigen::Matrix2d wheelTravelCovariance(double d_right, double d_left, double half_track, double variance_per_metre) {
  const double qr = variance_per_metre * std::fabs(d_right), ql = variance_per_metre * std::fabs(d_left);
  Eigen::Matrix2d c;
  c(0, 0) = 0.25 * (qr + ql);
  c(1, 1) = 0.25 * (qr + ql) / (half_track * half_track);
  c(0, 1) = c(1, 0) = 0.25 * (qr - ql) / half_track;
  return c;
}

Eigen::Matrix2d encoderIncrementCovariance(double increment_sigma, double half_track) {
  const double q = increment_sigma * increment_sigma;
  Eigen::Matrix2d c = Eigen::Matrix2d::Zero();
  c(0, 0) = 0.5 * q;
  c(1, 1) = 0.5 * q / (half_track * half_track);
  return c;
}

void FixQueue::push(const EkfFix& fix) {
  if (fixes_.size() >= capacity_) {
    fixes_.pop_front();
    ++dropped_;
  }
  // Keep stamp order (fixes normally come in order: this is one comparison).
  auto it = fixes_.end();
  while (it != fixes_.begin() && std::prev(it)->stamp > fix.stamp) --it;
  fixes_.insert(it, fix);
}

const std::vector<EkfFix>& FixQueue::due(double t) {
  due_.clear();  // its storage kept: no allocation per call
  while (!fixes_.empty() && fixes_.front().stamp + delay_ <= t + kStampTolerance) {
    due_.push_back(fixes_.front());
    fixes_.pop_front();
  }
  return due_;
}

}  // namespace core
}  // namespace sowing_robot
