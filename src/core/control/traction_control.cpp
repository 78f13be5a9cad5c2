#include "sowing_robot/core/control/traction_control.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

const ParamTable<TractionControlParams>& tractionControlTable() {
  using P = TractionControlParams;
  static const ParamTable<P> table({
      flag("traction_control/enabled", &P::enabled, false,
           "cap each wheel's torque while it slips beyond slip_target; false: the torques pass unchanged"),
      number("traction_control/slip_target", &P::slip_target, 0.15, Limits::above(0.0, 1.0), "",
             "|slip ratio| above which the wheel's torque is cut (the friction peak: traction/slip_peak)"),
      number("traction_control/speed_floor", &P::speed_floor, 0.1, Limits::positive(), "m/s",
             "smallest speed the estimated slip ratio is divided by"),
      number("traction_control/cut_rate", &P::cut_rate, 20.0, Limits::positive(), "1/s",
             "exponential fall of a slipping wheel's torque ceiling"),
      number("traction_control/raise_rate", &P::raise_rate, 2.0, Limits::positive(), "N·m/s",
             "linear rise of a gripping wheel's torque ceiling"),
      number("traction_control/min_torque", &P::min_torque, 0.3, Limits::nonNegative(), "N·m",
             "the ceiling never falls below this"),
      number("traction_control/max_torque", &P::max_torque, 100.0, Limits::positive(), "N·m",
             "the ceiling's top and its value at the start"),
      flag("traction_control/anti_windup", &P::anti_windup, false,
           "tell the inner loop which torques were held back, so that its integrators (PID integral, sliding-mode "
           "surface integral and adaptation) do not wind up against the ceiling"),
      number("traction_control/max_ground_accel", &P::max_ground_accel, 0.0, Limits::nonNegative(), "m/s^2",
             "the fastest the robot can speed up or slow down over ground: the fed speed is followed no faster, so "
             "wheels that spin up (or lock) together show their slip; 0 = the fed speed as it is"),
      number("traction_control/no_traction_window", &P::no_traction_window, 5.0, Limits::nonNegative(), "s",
             "no traction: this long without no_traction_progress of ground progress, the wheels slipping for "
             "no_traction_slip_share of it, and the robot is stopped and the run ends (0 = never)"),
      number("traction_control/no_traction_progress", &P::no_traction_progress, 0.25, Limits::positive(), "m",
             "no traction: the ground progress (fed pose) that restarts the window"),
      number("traction_control/no_traction_slip_share", &P::no_traction_slip_share, 0.5, Limits::above(0.0, 1.0), "",
             "no traction: the share of the window the wheels must have slipped"),
      number("traction_control/no_traction_hold", &P::no_traction_hold, 3.0, Limits::nonNegative(), "s",
             "no traction: the robot is held at rest this long after the verdict, then the run ends"),
  });
  return table;
}

TractionControlParams::TractionControlParams() { tractionControlTable().applyDefaults(*this); }

std::string TractionControlParams::validate() const {
  const std::string e = tractionControlTable().checkRanges(*this);
  if (!e.empty()) return e;
  if (min_torque > max_torque)
    return "traction_control/min_torque " + formatNumber(min_torque) +
           " N·m must not exceed traction_control/max_torque " + formatNumber(max_torque) + " N·m";
  return "";
}

TractionControl::TractionControl(const TractionControlParams& params, double L) : params_(params), L_(L) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  if (!(std::isfinite(L) && L > 0.0)) throw std::invalid_argument("traction control: half track L must be > 0");
  reset();
}

void TractionControl::reset() {
  ceiling_[0] = ceiling_[1] = params_.max_torque;
  slip_[0] = slip_[1] = sent_[0] = sent_[1] = 0.0;
  slipping_ = limiting_ = slipping_as_fed_ = false;
  have_ground_ = false;
}

/// The slip ratio of a wheel turning at wheel_speed over ground moving at ground_speed (0 when either is not finite).
double TractionControl::slipRatio(double wheel_speed, double ground_speed) const {
  const double scale = std::max({std::fabs(wheel_speed), std::fabs(ground_speed), params_.speed_floor});
  return std::isfinite(wheel_speed) && std::isfinite(ground_speed) ? (wheel_speed - ground_speed) / scale : 0.0;
}

double TractionControl::limitWheel(int wheel, double command, double wheel_speed, double ground_speed, double dt) {
  slip_[wheel] = slipRatio(wheel_speed, ground_speed);
  double& ceiling = ceiling_[wheel];
  if (std::fabs(slip_[wheel]) > params_.slip_target) {
    slipping_ = true;
    // From the torque that made it slip, not from a ceiling far above it: the cut bites at once.
    ceiling =
        std::max(params_.min_torque, std::min(ceiling, std::fabs(sent_[wheel])) * std::exp(-params_.cut_rate * dt));
  } else {
    ceiling = std::min(params_.max_torque, ceiling + params_.raise_rate * dt);
  }
  sent_[wheel] = std::clamp(command, -ceiling, ceiling);
  if (sent_[wheel] != command) limiting_ = true;
  return sent_[wheel];
}

WheelTorques TractionControl::limit(const WheelTorques& command, const WheelGroundSpeeds& m, double dt) {
  if (!params_.enabled) return command;
  slipping_ = limiting_ = slipping_as_fed_ = false;
  WheelTorques out;
  // A fed speed that follows the encoders (odometry, or the EKF between fixes) rises with wheels that spin up
  // together, so their slip would not show; the ground cannot speed the robot up faster than its grip allows,
  // so the reference speed follows the fed one only that fast (automotive traction control's slope-limited
  // reference speed for a vehicle with every wheel driven). The yaw rate is taken as fed: the gyro's, which
  // wheel spin does not drive, and which a sharp turn may change faster than any such bound.
  double v = m.v;
  const bool bounded = params_.max_ground_accel > 0.0 && std::isfinite(v);
  if (bounded) {
    if (!have_ground_) {
      ground_ = v;
      have_ground_ = true;
    }
    const double step = params_.max_ground_accel * dt;
    v = ground_ = std::clamp(v, ground_ - step, ground_ + step);
  }
  out.right = limitWheel(0, command.right, m.wheel_right, v + L_ * m.omega, dt);
  out.left = limitWheel(1, command.left, m.wheel_left, v - L_ * m.omega, dt);
  slipping_as_fed_ = bounded ? std::fabs(slipRatio(m.wheel_right, m.v + L_ * m.omega)) > params_.slip_target ||
                                   std::fabs(slipRatio(m.wheel_left, m.v - L_ * m.omega)) > params_.slip_target
                             : slipping_;
  return out;
}

}  // namespace core
}  // namespace sowing_robot
