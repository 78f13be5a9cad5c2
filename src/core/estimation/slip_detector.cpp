#include "sowing_robot/core/estimation/slip_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sowing_robot {
namespace core {
namespace {

// The CUSUM's allowance [std]: half the 1-std shift it is tuned to see (Page's choice); with the default
// threshold 5 a false alarm comes every ~900 unbiased fixes, a 1-std bias alarms within ~10.
constexpr double kCusumAllowance = 0.5;
// The quick average's time constant, a fraction of window: against the window's average it shows an
// acceleration within a fifth of the window, and a step in speed as well as a ramp.
constexpr double kQuick = 0.2;

}  // namespace

const ParamTable<SlipParams>& slipParamsTable() {
  using P = SlipParams;
  static const ParamTable<P> table({
      flag("detect", &P::detect, false,
           "the slip-aware filter: the ground speed and each wheel's slip speed in the state, a wheel's encoder "
           "left out while it breaks loose; false: the filter without"),
      number("max_ground_speed", &P::max_ground_speed, 3.0, Limits::above(0.0, 100.0), "m/s",
             "no ground speed beyond this (the drive's top speed: the motors' no-load speed at the rim is 2.9 m/s): "
             "a wheel claiming more is loose, the speed estimate is held within it"),
      number("max_acceleration", &P::max_acceleration, 6.0, Limits::above(0.0, 1000.0), "m/s²",
             "no ground acceleration beyond this (the grip, μ_peak g with the drive wheels' share of the weight): a "
             "wheel's speed changing faster is loose"),
      number("speed_tolerance", &P::speed_tolerance, 0.05, Limits::above(0.0, 10.0), "m/s",
             "a wheel whose estimated slip speed exceeds this is reported as slipping (and the fixes then correct "
             "neither heading nor bias while both do)"),
      number("window", &P::window, 0.05, Limits::above(0.0, 10.0), "s",
             "time constant of the averaged wheel speeds the tests compare (the encoders' quantisation averaged out)"),
      number("cusum_threshold", &P::cusum_threshold, 5.0, Limits::closed(0.0, 1000.0), "",
             "alarm level of the CUSUM of the fixes' along-track innovations (in standard deviations, allowance "
             "0.5): an alarm re-opens both wheels' slips; 0: off"),
      number("speed_walk", &P::speed_walk, 0.5, Limits::above(0.0, 100.0), "m/s/√s",
             "random walk of the ground speed (how fast it may change while no wheel measures it)"),
      number("slip_walk", &P::slip_walk, 0.05, Limits::above(0.0, 100.0), "m/s/√s",
             "random walk of each wheel's slip speed (how fast slip may build up or fade without a loose wheel)"),
      number("slip_rate", &P::slip_rate, 1.0, Limits::closed(0.0, 100.0), "1/√s",
             "the slip's random walk grows by this times the slip (a wheel far out of grip changes its slip fast)"),
  });
  return table;
}

SlipParams::SlipParams() { slipParamsTable().applyDefaults(*this); }

std::string SlipParams::validate() const { return slipParamsTable().checkRanges(*this, "estimator/slip/"); }

SlipDetector::SlipDetector(const SlipParams& params, double half_track) : params_(params), L_(half_track) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  if (!(std::isfinite(half_track) && half_track > 0.0))
    throw std::invalid_argument("SlipDetector: the half track must be finite and > 0");
}

void SlipDetector::reset() {
  primed_ = false;
  loose_ = SLIP_NONE;
  cusum_ahead_ = cusum_behind_ = 0.0;
  last_fix_ = ahead_since_ = behind_since_ = 0.0;
}

unsigned SlipDetector::step(const SlipEvidence& e, unsigned& onset) {
  onset = SLIP_NONE;
  if (!(e.dt > 0.0)) return loose_;
  // The body's yaw rate: the gyro's, or the encoders' when there is none.
  const double rate = e.has_rate ? e.rate : (e.travel_right - e.travel_left) / (2.0 * L_ * e.dt);
  const double claim[2] = {e.travel_right / e.dt - L_ * rate, e.travel_left / e.dt + L_ * rate};
  if (!primed_) {
    for (int i = 0; i < 2; ++i) quick_[i] = smooth_[i] = claim[i];
    primed_ = true;
  } else {
    const double a_quick = std::min(1.0, e.dt / (kQuick * params_.window)), a = std::min(1.0, e.dt / params_.window);
    for (int i = 0; i < 2; ++i) {
      quick_[i] += a_quick * (claim[i] - quick_[i]);
      smooth_[i] += a * (claim[i] - smooth_[i]);
    }
  }
  // Beyond what the ground can do: too fast, or speeding up or slowing down faster than the grip allows
  // (the two averages of a ramp a lie a (1 - kQuick) window apart; a step shows as a steeper ramp).
  const unsigned bit[2] = {SLIP_RIGHT, SLIP_LEFT};
  unsigned loose = SLIP_NONE;
  for (int i = 0; i < 2; ++i) {
    const double acceleration = (quick_[i] - smooth_[i]) / ((1.0 - kQuick) * params_.window);
    if (std::fabs(smooth_[i]) > params_.max_ground_speed || std::fabs(acceleration) > params_.max_acceleration)
      loose |= bit[i];
  }
  onset = loose & ~loose_;
  for (int i = 0; i < 2; ++i)
    if (onset & bit[i]) ++counts_.loose;
  loose_ = loose;
  return loose_;
}

double SlipDetector::fix(double stamp, double along) {
  if (params_.cusum_threshold <= 0.0 || !std::isfinite(along)) return 0.0;
  // Each side's sum, and the stamp of the fix before it last left zero (where its evidence starts).
  const auto side = [&](double& sum, double& since, double increment) {
    if (sum <= 0.0) since = last_fix_;
    sum = std::max(0.0, sum + increment - kCusumAllowance);
  };
  side(cusum_ahead_, ahead_since_, along);
  side(cusum_behind_, behind_since_, -along);
  last_fix_ = stamp;
  double since = 0.0;
  if (cusum_ahead_ > params_.cusum_threshold)
    since = ahead_since_;
  else if (cusum_behind_ > params_.cusum_threshold)
    since = behind_since_;
  else
    return 0.0;
  cusum_ahead_ = cusum_behind_ = 0.0;
  ++counts_.by_fixes;
  return std::max(stamp - since, 1e-9);
}

}  // namespace core
}  // namespace sowing_robot
