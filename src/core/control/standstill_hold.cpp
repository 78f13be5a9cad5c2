#include "sowing_robot/core/control/standstill_hold.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

const ParamTable<StandstillHoldParams>& standstillHoldTable() {
  using P = StandstillHoldParams;
  static const ParamTable<P> table({
      number("hold/bandwidth", &P::bandwidth, 100.0, Limits::positive(), "rad/s",
             "standstill hold at a stop: natural frequency of its brake on both axes (at most 0.25 / control period)"),
      number("hold/damping", &P::damping, 0.7, Limits::positive(), "", "standstill hold: damping ratio"),
  });
  return table;
}

StandstillHoldParams::StandstillHoldParams() { standstillHoldTable().applyDefaults(*this); }

std::string StandstillHoldParams::validate() const { return standstillHoldTable().checkRanges(*this); }

StandstillHold::StandstillHold(const StandstillHoldParams& params, const RobotParams& nominal, double max_torque)
    : params_(params),
      m0R_(nominal.m0() * nominal.R),
      i0RL_(nominal.I0() * nominal.R / nominal.L),
      max_torque_(max_torque) {
  const std::string e = firstError({params.validate(), nominal.validate()});
  if (!e.empty()) throw std::invalid_argument(e);
  if (!(max_torque > 0.0)) throw std::invalid_argument("standstill hold: max_torque must be > 0");
}

namespace {
/// `spring` moved to `target` if that lies between zero and it; to zero if `target` is beyond zero; else unchanged.
double towardZero(double spring, double target) {
  if (spring * target <= 0.0) return 0.0;
  return std::fabs(target) < std::fabs(spring) ? target : spring;
}
}  // namespace

HoldTorques StandstillHold::update(double v, double omega, double dt) {
  if (!std::isfinite(v)) v = 0.0;  // a lost reading: taken as standing still
  if (!std::isfinite(omega)) omega = 0.0;
  x_ += v * dt;
  theta_ += omega * dt;
  const double wn = std::min(params_.bandwidth, kMaxBandwidthPeriods / dt);
  const double damp = 2.0 * params_.damping * wn, stiff = wn * wn;
  v_ = v;
  omega_ = omega;
  damp_ = damp;
  stiff_ = stiff;
  HoldTorques out;
  out.u1 = -m0R_ * (damp * v + stiff * x_);
  out.u2 = -i0RL_ * (damp * omega + stiff * theta_);
  const double right = 0.5 * (out.u1 + out.u2), left = 0.5 * (out.u1 - out.u2);
  out.torques.right = std::clamp(right, -max_torque_, max_torque_);
  out.torques.left = std::clamp(left, -max_torque_, max_torque_);
  out.saturated = out.torques.right != right || out.torques.left != left;
  last_ = out;
  if (out.saturated) backCalculate(out.torques.right + out.torques.left, out.torques.right - out.torques.left);
  return out;
}

void StandstillHold::heldBack(const WheelTorques& sent) {
  if (sent.right == last_.torques.right && sent.left == last_.torques.left) return;  // all of it went out
  backCalculate(sent.right + sent.left, sent.right - sent.left);
}

void StandstillHold::backCalculate(double sent_u1, double sent_u2) {
  // On each axis that asked more than went out, the spring's stretch at which the brake would have asked
  // exactly that, if it is nearer zero than the spring's own (never past zero: with the damping alone beyond
  // the limit the spring is emptied). So x, theta never store torque the wheels did not get.
  if (std::fabs(last_.u1) > std::fabs(sent_u1)) x_ = towardZero(x_, (-sent_u1 / m0R_ - damp_ * v_) / stiff_);
  if (std::fabs(last_.u2) > std::fabs(sent_u2))
    theta_ = towardZero(theta_, (-sent_u2 / i0RL_ - damp_ * omega_) / stiff_);
}

}  // namespace core
}  // namespace sowing_robot
