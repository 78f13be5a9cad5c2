// The outer loop's output limits: bounds on the velocity command that any outer controller hands the inner
// loop, as a real drive's velocity and acceleration limits (diff_drive_controller's linear/angular limits, the
// max speed and acceleration of nav2's controllers). Kanayama's v = v_r cos(theta_e) + kx x_e and RPP's
// v_r + k_along x_e grow with the error: joining a line from metres away they ask for several m/s and m/s^2,
// which wet soil cannot carry (its grip budget, docs/drive_train.md), so the wheels spin or lock and the robot
// overshoots the line. With the limits on, each of v and omega is clamped to +-max and may change by at most
// max_accel dt per period (a slew limit); the accelerations handed on (v_dot, omega_dot) are those of the
// limited command when a bound acts, else the controller's own. A hold (a stop) passes unchanged and restarts
// the slew from rest. Off (the default): the command passes unchanged, bit for bit.
#pragma once

#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"

namespace sowing_robot {
namespace core {

/// Defaults, ranges, units and meanings: commandLimitsTable().
struct CommandLimitsParams {
  CommandLimitsParams();
  bool enabled;              ///< false: the command passes unchanged
  double max_v;              ///< [m/s] bound on |v|
  double max_omega;          ///< [rad/s] bound on |omega|
  double max_acceleration;   ///< [m/s^2] bound on the change of v
  double max_angular_accel;  ///< [rad/s^2] bound on the change of omega
  std::string validate() const;
};
/// limits/{enabled, max_v, max_omega, max_acceleration, max_angular_accel}.
const ParamTable<CommandLimitsParams>& commandLimitsTable();

class CommandLimiter {
 public:
  /// Throws std::invalid_argument when the parameters do not validate.
  explicit CommandLimiter(const CommandLimitsParams& params);
  /// From rest.
  void reset() { v_ = omega_ = 0.0; }
  /// The command to hand on for the outer controller's `cmd` this period of dt [s] (> 0).
  VelocityCommand limit(const VelocityCommand& cmd, double dt);
  /// Either bound changed the last command.
  bool limiting() const { return limiting_; }
  const CommandLimitsParams& params() const { return params_; }

 private:
  CommandLimitsParams params_;
  double v_ = 0.0, omega_ = 0.0;  ///< the last command handed on [m/s], [rad/s]
  bool limiting_ = false;
};

}  // namespace core
}  // namespace sowing_robot
