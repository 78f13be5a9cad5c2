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
  HoldTorques update(double v, double omega, double dt);
  const StandstillHoldParams& params() const { return params_; }

 private:
  StandstillHoldParams params_;
  double m0R_, i0RL_;  ///< m0 R [kg·m], I0 R / L [kg·m]
  double max_torque_;
  double x_ = 0.0, theta_ = 0.0;  ///< displacement and turn since engage() [m], [rad]
};

}  // namespace core
}  // namespace sowing_robot
