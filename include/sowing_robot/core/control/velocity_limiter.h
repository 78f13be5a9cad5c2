// The velocity limiter of velocity mode (cmd_vel; docs/interfaces.md): v and omega each follow the
// time-optimal profile to their target under bounds on the value, its acceleration and its jerk, the same
// bounds in both directions (reverse). diff_drive_controller's speed_limiter clamps finite differences of
// the command, so its accelerations are not those of the velocity it outputs; here each axis moves along
// an analytic profile of piecewise-constant jerk, so the accelerations handed to the inner loop (v_dot,
// omega_dot) are the exact derivatives of the velocities it is given, whatever the step length.
#pragma once

#include <array>
#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"

namespace sowing_robot {
namespace core {

/// The bounds of one axis (v or omega), the same forward and in reverse.
struct AxisLimits {
  double max_velocity;      ///< bound on |value| [m/s] or [rad/s]
  double max_acceleration;  ///< [m/s^2] or [rad/s^2]
  double max_jerk;          ///< [m/s^3] or [rad/s^3]
};

/// Defaults, ranges and units: velocityLimitsTable().
struct VelocityLimits {
  VelocityLimits();
  double v_max, v_acceleration, v_jerk;              ///< linear/...  [m/s], [m/s^2], [m/s^3]
  double omega_max, omega_acceleration, omega_jerk;  ///< angular/... [rad/s], [rad/s^2], [rad/s^3]
  AxisLimits linear() const { return {v_max, v_acceleration, v_jerk}; }
  AxisLimits angular() const { return {omega_max, omega_acceleration, omega_jerk}; }
  std::string validate() const;
};
/// linear/{max_velocity, max_acceleration, max_jerk}, angular/{...}.
const ParamTable<VelocityLimits>& velocityLimitsTable();

/// One axis: its value and its acceleration (continuous: the jerk is bounded).
struct AxisState {
  double value = 0.0;         ///< [m/s] or [rad/s]
  double acceleration = 0.0;  ///< [m/s^2] or [rad/s^2]
};

/// The time-optimal way from a state to (target, 0) within an axis's bounds: up to three phases of
/// constant jerk (towards the peak acceleration, hold it, back to zero).
struct JerkProfile {
  struct Phase {
    double jerk = 0.0;      ///< [unit/s^3]
    double duration = 0.0;  ///< [s]
  };
  std::array<Phase, 3> phases;
  double target = 0.0;  ///< the target, clamped to +-max_velocity

  /// [s]
  double duration() const;
  /// The state `t` seconds after `start` along the profile; from duration() on, exactly (target, 0).
  AxisState at(const AxisState& start, double t) const;
};

/// The profile from `s` to `target` (clamped to +-max_velocity). From a state that such profiles reach
/// (|acceleration| <= max_acceleration and no overshoot pending), it stays within every bound: it never
/// overshoots its target, so |value| never passes max_velocity.
JerkProfile planProfile(const AxisState& s, double target, const AxisLimits& limits);

/// Both axes, each along its profile, from rest.
class VelocityLimiter {
 public:
  /// Throws std::invalid_argument when the limits do not validate.
  explicit VelocityLimiter(const VelocityLimits& limits);

  /// Moves both axes dt [s] (>= 0) towards (v, omega), each clamped to its max_velocity.
  void advance(double v, double omega, double dt);
  /// The velocities and accelerations now: what the inner loop is given.
  VelocityCommand command() const { return {v_.value, omega_.value, v_.acceleration, omega_.acceleration}; }
  /// At rest.
  void reset() { v_ = omega_ = AxisState(); }
  /// |v| and |omega| within their max_velocity.
  bool withinBounds(double v, double omega) const;
  const VelocityLimits& limits() const { return limits_; }

 private:
  VelocityLimits limits_;
  AxisLimits linear_, angular_;
  AxisState v_, omega_;
};

}  // namespace core
}  // namespace sowing_robot
