// The standstill hold ("a stop is a stop"): what the drive does while the plan holds the robot at rest
// (VelocityCommand::hold), as a motor drive's zero-speed hold: the robot is held where the hold began.
// The inner loop's own states (sliding integrals, adaptive estimates, PID integrals) are frozen meanwhile
// (its output is zero torque with `holding`), so nothing winds up at rest and it resumes from where it
// stopped; this brake alone sets the torques.
//
// A stiff position hold about where the hold began, on the body's two axes (the ones the inner loops
// split the torque into, eq 4.10), from the fed twist (the drive's own measure):
//   x = int v dt, theta = int omega dt since the hold began,
//   tau_r + tau_l = -m0 R (2 zeta w_n v + w_n^2 x),   tau_r - tau_l = -(I0 R / L) (2 zeta w_n omega + w_n^2 theta),
// so each axis of the nominal model behaves as a mass on a spring of natural frequency w_n and damping
// ratio zeta. A velocity-only hold would have to out-damp the whole disturbance; the position term holds a
// steady push without an integral that could wind up, and keeps the robot from creeping. Each wheel's
// torque is clipped at the motor limit. A sampled PD is stable only while w_n dt stays well below 1, so
// the bandwidth in use is at most kMaxBandwidthPeriods / dt. What it holds against, on which plant and
// feedback, and where it cannot (a wheel the soil cannot hold against the disturbance): docs/stops.md.
//
// It never winds up: x and theta are the spring's stretch, and whatever part of the brake's torque does not
// reach the wheels (clipped at the motor limit here, or cut by the traction control after it: heldBack) is
// taken back out of them, so the spring never stores more than the torque that was applied (back-calculation,
// as a drive's anti-windup). Without it a brake whose torque was capped (the traction control's ceiling, a
// few N·m on soil) went on stretching its spring on every count of measured motion, until it asked the
// motor's full 100 N·m and broke the wheels loose (the field profile, fed the EKF: docs/stops.md).
//
// What it closes on: the fed twist; fed the EKF (with the traction control on, which brings the encoders' rates
// to the loop), its along axis on the wheels' own encoder rates (wheelSpeed) instead of the EKF's ground speed:
// that estimate's noise is beyond what the stiff brake can damp on and its spring, integrating it, walks; the
// encoders' rates integrate to the wheels' counted travel, which does not drift. The yaw axis stays on the fed
// yaw rate (the gyro less the EKF's bias): finer than the encoders' difference (one count is 0.55 mrad of yaw).
#pragma once

#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/model/robot_params.h"

namespace sowing_robot {
namespace core {

/// Defaults, ranges, units and meanings: standstillHoldTable().
struct StandstillHoldParams {
  StandstillHoldParams();
  double bandwidth;  ///< w_n of both axes [rad/s]
  double damping;    ///< zeta [-]
  std::string validate() const;
};
/// hold/bandwidth, hold/damping.
const ParamTable<StandstillHoldParams>& standstillHoldTable();

/// The brake's torques of one period.
struct HoldTorques {
  WheelTorques torques;
  double u1 = 0.0, u2 = 0.0;  ///< tau_r + tau_l, tau_r - tau_l before clipping [N·m]
  bool saturated = false;
};

class StandstillHold {
 public:
  /// w_n dt is kept at or below this (a sampled PD's margin).
  static constexpr double kMaxBandwidthPeriods = 0.25;

  /// `nominal` gives m0, I0, R, L; max_torque is the motor's per-wheel limit [N·m]. Throws
  /// std::invalid_argument when either set does not validate or max_torque is not > 0.
  StandstillHold(const StandstillHoldParams& params, const RobotParams& nominal, double max_torque);

  /// The hold begins here: x and theta from zero.
  void engage() { x_ = theta_ = 0.0; }
  /// One period of dt [s] (> 0) at the fed twist v [m/s], omega [rad/s] (a non-finite one counts as 0).
  /// A wheel's torque clipped at the motor limit is taken back out of the spring (no windup).
  HoldTorques update(double v, double omega, double dt);
  /// The torques that reached the wheels this period (after the traction control): what of the brake's
  /// torques was held back is taken out of the spring, as update() does for the motor limit.
  void heldBack(const WheelTorques& sent);
  /// The body's speed from the wheels' own rates (R W of each, e.g. from the encoders): (right + left) / 2 [m/s].
  static double wheelSpeed(double right, double left) { return 0.5 * (right + left); }
  double stretch() const { return x_; }   ///< x since engage() [m]
  double turn() const { return theta_; }  ///< theta since engage() [rad]
  const StandstillHoldParams& params() const { return params_; }

 private:
  StandstillHoldParams params_;
  double m0R_, i0RL_;  ///< m0 R [kg·m], I0 R / L [kg·m]
  double max_torque_;
  double x_ = 0.0, theta_ = 0.0;                             ///< displacement and turn since engage() [m], [rad]
  double v_ = 0.0, omega_ = 0.0, damp_ = 0.0, stiff_ = 1.0;  ///< the last update's twist and gains
  HoldTorques last_;                                         ///< the last update's answer
  /// Takes out of x, theta what of the torques u1, u2 asked did not reach the wheels (sent sum / difference).
  void backCalculate(double sent_u1, double sent_u2);
};

}  // namespace core
}  // namespace sowing_robot
