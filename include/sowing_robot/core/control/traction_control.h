// Traction control: a layer between any inner loop and the motors that keeps each drive wheel near the
// friction peak by capping its torque, as automotive traction control (torque reduction on wheel spin)
// and tractor slip control do. Chosen over slip-ratio regulation with its own PI loop because it needs
// no model of the soil and leaves the inner loop in charge whenever the wheels grip: it only ever lowers
// a torque, and only on a wheel that slips.
//
// Each period, per wheel: the slip is estimated from what the robot measures, the wheel's own speed
// (its encoder: R W) against the ground speed of its contact point (v ± L w of the estimator's or the fed
// body twist, never the plant's hidden state),
//     kappa = (R W - u) / max(|R W|, |u|, speed_floor);
// while |kappa| > slip_target the wheel's torque ceiling falls exponentially (cut_rate) from the torque
// last sent, else it rises linearly (raise_rate) back to max_torque; the command is clipped to
// [-ceiling, ceiling]. So the ceiling settles about the largest torque the soil carries at the target
// slip (additive increase, multiplicative decrease).
//
// With max_ground_accel > 0 the body's speed v in u is not taken as fed: a reference speed follows the fed one
// at most that fast (a slope-limited reference speed, as automotive traction control estimates the speed of a
// vehicle whose every wheel is driven). A fed speed built from the encoders rises with wheels that spin up
// together, and would hide their slip; the reference does not rise faster than the soil can push. The yaw
// rate stays as fed (the gyro's: wheel spin does not drive it).
#pragma once

#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"

namespace sowing_robot {
namespace core {

/// Defaults, ranges, units and meanings: tractionControlTable().
struct TractionControlParams {
  TractionControlParams();
  bool enabled;        ///< false: the torques pass unchanged
  double slip_target;  ///< |slip ratio| above which the torque is cut (the friction curve's peak)
  double speed_floor;  ///< [m/s] smallest speed the slip ratio is divided by
  double cut_rate;     ///< [1/s] exponential fall of the ceiling while the wheel slips
  double raise_rate;   ///< [N·m/s] linear rise of the ceiling while it grips
  double min_torque;   ///< [N·m] the ceiling never falls below this (the wheel can always pull away)
  double max_torque;   ///< [N·m] the ceiling's top (and its value at reset)
  /// Tell the inner loop which torques were held back, so that its integrators do not wind up against
  /// the ceiling (InnerController::heldBack).
  bool anti_windup;
  /// [m/s^2] the fastest the reference ground speed follows the fed v (0: the fed speed as it is).
  double max_ground_accel;

  /// No traction (traction_monitor.h): the window [s] (0: never), the progress that restarts it [m], the
  /// share of it the wheels must slip [-], and how long the robot is held after the verdict [s].
  double no_traction_window, no_traction_progress, no_traction_slip_share, no_traction_hold;

  std::string validate() const;
};
/// traction_control/{enabled, slip_target, speed_floor, cut_rate, raise_rate, min_torque, max_torque, anti_windup,
/// max_ground_accel, no_traction_window, no_traction_progress, no_traction_slip_share, no_traction_hold}.
const ParamTable<TractionControlParams>& tractionControlTable();

/// What the layer measures in one period.
struct WheelGroundSpeeds {
  double wheel_right, wheel_left;  ///< R W of each wheel, from its encoder [m/s]
  double v, omega;                 ///< the body's ground twist, from the estimator or the fed state [m/s, rad/s]
};

class TractionControl {
 public:
  /// R: nothing (the wheel speeds come as R W); L: the nominal half track [m]. Throws std::invalid_argument
  /// when the parameters do not validate or L is not finite and > 0.
  TractionControl(const TractionControlParams& params, double L);
  void reset();
  /// The torques to send [N·m] for the inner loop's `command` this period.
  WheelTorques limit(const WheelTorques& command, const WheelGroundSpeeds& m, double dt);

  /// The last estimate of each wheel's slip ratio (0 right, 1 left).
  double slip(int wheel) const { return slip_[wheel]; }
  double ceiling(int wheel) const { return ceiling_[wheel]; }
  /// Either wheel slipped beyond the target in the last period.
  bool slipping() const { return slipping_; }
  /// The same against the fed ground speed as it is, without max_ground_accel's bound (with the bound off:
  /// slipping()). What the no-traction check reads: the bounded reference also reads a fed speed swinging faster
  /// than the bound (an aggressive inner loop) as slip, and a stop that ends the run must not fire on that.
  bool slippingAsFed() const { return slipping_as_fed_; }
  /// Either wheel's command was cut to its ceiling in the last period: the inner loop asked for more
  /// torque than the soil has carried (the wheel is held at the friction peak). This, not slipping(), is
  /// the grip-limit verdict while the control works: it keeps the slip about the target, so slipping()
  /// fires only in the short bursts that cut the ceiling.
  bool limiting() const { return limiting_; }
  const TractionControlParams& params() const { return params_; }

 private:
  double limitWheel(int wheel, double command, double wheel_speed, double ground_speed, double dt);
  double slipRatio(double wheel_speed, double ground_speed) const;

  TractionControlParams params_;
  double L_;
  double ceiling_[2], slip_[2] = {0.0, 0.0}, sent_[2] = {0.0, 0.0};
  double ground_ = 0.0;       ///< the reference ground speed of the body (max_ground_accel) [m/s]
  bool have_ground_ = false;  ///< false until the first finite fed twist after a reset
  bool slipping_ = false, limiting_ = false, slipping_as_fed_ = false;
};

}  // namespace core
}  // namespace sowing_robot
