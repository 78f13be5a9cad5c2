#include "sowing_robot/core/control/wheel_pid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

const ParamTable<WheelPidParams>& wheelPidTable() {
  using P = WheelPidParams;
  static const ParamTable<P> table({
      tunable(number("kp", &P::kp, 2.0, Limits::nonNegative(), "N·m·s/rad", "proportional gain on wheel speed")),
      tunable(number("ki", &P::ki, 20.0, Limits::nonNegative(), "N·m/rad", "integral gain on wheel speed")),
      tunable(number("kd", &P::kd, 0.0, Limits::nonNegative(), "N·m·s^2/rad",
                     "derivative gain, on the measured wheel speed")),
      tunable(number("feedforward", &P::feedforward, 1.0, Limits::closed(0.0, 2.0), "",
                     "scale of the nominal inertia feedforward m0 R v_dot, I0 R/L omega_dot (0 = none)")),
      number("max_torque", &P::max_torque, 100.0, Limits::positive(), "N·m",
             "per-wheel motor limit; clipping is reported"),
      flag("anti_windup", &P::anti_windup, true,
           "clamp the integral term at max_torque and hold it while the output saturates"),
  });
  return table;
}

WheelPidParams::WheelPidParams() { wheelPidTable().applyDefaults(*this); }

std::string WheelPidParams::validate() const { return wheelPidTable().checkRanges(*this); }

WheelPid::WheelPid(const WheelPidParams& params, const RobotParams& nominal)
    : params_(params), R_(nominal.R), L_(nominal.L), m0_(nominal.m0()), i0_(nominal.I0()) {
  const std::string error = firstError({params.validate(), nominal.validate()});
  if (!error.empty()) throw std::invalid_argument(error);
  reset();
}

void WheelPid::reset() {
  right_ = left_ = Wheel{};
  last_output_ = WheelPidOutput{};
}

void WheelPid::setParams(const WheelPidParams& params) {
  const std::string error = params.validate();
  if (!error.empty()) throw std::invalid_argument(error);
  params_ = params;
}

double WheelPid::wheel(Wheel& s, double w_d, double w, double ff, double dt, double& e, double& i_term) const {
  e = w_d - w;
  const double d_term = s.has_last ? -params_.kd * (w - s.last_w) / dt : 0.0;
  const double rest = ff + params_.kp * e + d_term;
  double integral = s.integral + e * dt;
  if (params_.anti_windup) {
    const double limit = params_.max_torque;
    const double u_candidate = rest + params_.ki * integral;
    // Conditional integration: do not integrate further into a saturated output, nor into one a layer
    // after this controller held back (heldBack).
    if ((u_candidate > limit && e > 0.0) || (u_candidate < -limit && e < 0.0) || (s.held > 0 && e > 0.0) ||
        (s.held < 0 && e < 0.0))
      integral = s.integral;
    // Clamping: the integral term alone never exceeds the motor limit.
    if (params_.ki > 0.0) integral = std::clamp(integral, -limit / params_.ki, limit / params_.ki);
  }
  s.integral = integral;
  s.held = 0;
  s.last_w = w;
  s.has_last = true;
  i_term = params_.ki * integral;
  return rest + i_term;
}

void WheelPid::heldBack(const WheelTorques& sent) {
  const auto held = [](double out, double got) { return got < out ? 1 : got > out ? -1 : 0; };
  right_.held = held(last_output_.torques.right, sent.right);
  left_.held = held(last_output_.torques.left, sent.left);
}

WheelPidOutput WheelPid::update(const VelocityCommand& desired, double v, double omega, double dt) {
  if (!allFinite(desired.v, desired.omega, desired.v_dot, desired.omega_dot, v, omega, dt) || !(dt > 0.0)) {
    WheelPidOutput held = last_output_;
    held.rejected = true;
    return held;
  }
  if (desired.hold) {  // a stop: integrals frozen, the standstill hold brakes
    WheelPidOutput out;
    out.e_right = -(v + L_ * omega) / R_;
    out.e_left = -(v - L_ * omega) / R_;
    out.i_right = params_.ki * right_.integral;
    out.i_left = params_.ki * left_.integral;
    out.holding = true;
    right_.last_w = -out.e_right;
    left_.last_w = -out.e_left;
    right_.has_last = left_.has_last = true;
    last_output_ = out;
    return out;
  }
  const double sum = params_.feedforward * m0_ * R_ * desired.v_dot;            // tau_r + tau_l
  const double diff = params_.feedforward * i0_ * R_ / L_ * desired.omega_dot;  // tau_r - tau_l
  WheelPidOutput out;
  out.u_right = wheel(right_, (desired.v + L_ * desired.omega) / R_, (v + L_ * omega) / R_, 0.5 * (sum + diff), dt,
                      out.e_right, out.i_right);
  out.u_left = wheel(left_, (desired.v - L_ * desired.omega) / R_, (v - L_ * omega) / R_, 0.5 * (sum - diff), dt,
                     out.e_left, out.i_left);
  out.torques.right = std::clamp(out.u_right, -params_.max_torque, params_.max_torque);
  out.torques.left = std::clamp(out.u_left, -params_.max_torque, params_.max_torque);
  out.saturated = out.torques.right != out.u_right || out.torques.left != out.u_left;
  last_output_ = out;
  return out;
}

}  // namespace core
}  // namespace sowing_robot
