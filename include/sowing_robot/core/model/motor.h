// The drive motors: a brushed DC motor with a gearbox at each wheel, as the wheel sees it. The torque it
// can give falls linearly with the wheel's speed (back-EMF: the bus voltage drives the current through
// the winding resistance against the induced voltage), from the stall torque at rest to zero at the
// no-load speed, and the motor driver limits the current, so
//     tau in [max(-i_lim, -tau_s (1 + W / W_0)), min(i_lim, tau_s (1 - W / W_0))]
// with W the wheel's spin rate (the wheel's own, so a spinning wheel loses torque) and i_lim the torque
// at the current limit. Optionally the torque follows the clipped command with a first-order lag (the
// winding's L/R). A stalled robot can no longer spin its wheels beyond W_0: there the band is empty of
// driving torque.
//
// Defaults: a 150 W, 24 V brushed DC motor of the maxon RE 40 class with a 26:1 two-stage planetary
// gearbox (GP 42 C class, efficiency 0.81), on the robot's 0.095 m wheels. The catalogue figures used
// (quoted from the maker's data sheets as we know them; not re-checked against the current catalogue):
// no-load speed 7,580 rpm, stall torque 2.5 N·m, torque constant 30.2 mN·m/A, winding L/R 0.27 ms. At
// the wheel: W_0 = 7580 rpm / 26 = 30.5 rad/s (2.9 m/s), tau_s = 2.5 × 26 × 0.81 = 52.6 N·m, and a 10 A
// driver limit gives 0.0302 × 10 × 26 × 0.81 = 6.4 N·m (within the gearbox's continuous rating). The
// lag is off by default: L/R is shorter than the 1 ms control period.
#pragma once

#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/model/robot_params.h"

namespace sowing_robot {
namespace core {

/// Defaults, ranges, units and meanings: motorTable().
struct MotorParams {
  MotorParams();
  bool enabled;          ///< false: the commanded torque reaches the wheel unchanged (the controllers' clip only)
  double stall_torque;   ///< tau_s [N·m] at the wheel
  double no_load_speed;  ///< W_0 [rad/s] of the wheel
  double current_limit;  ///< i_lim [N·m]: the wheel torque at the driver's current limit
  double time_constant;  ///< [s] first-order lag of the torque behind the clipped command (0: none)

  std::string validate() const;
  /// The torque band at wheel speed w [rad/s]: lo <= tau <= hi.
  void band(double w, double& lo, double& hi) const;
};
/// motor/{enabled, stall_torque, no_load_speed, current_limit, time_constant}.
const ParamTable<MotorParams>& motorTable();

/// One wheel's motor: the torque it applies for a command.
class WheelMotor {
 public:
  explicit WheelMotor(const MotorParams& params = MotorParams()) : params_(params) {}
  void reset() { applied_ = 0.0; }
  /// The torque [N·m] applied over the next dt [s] for the command tau at wheel speed w [rad/s]; with the
  /// motor disabled, tau itself.
  double apply(double tau, double w, double dt);
  double applied() const { return applied_; }
  const MotorParams& params() const { return params_; }

 private:
  MotorParams params_;
  double applied_ = 0.0;
};

/// "" or one line naming the keys when the motors cannot move the robot from rest against the rolling
/// resistance and the draft: per wheel min(stall_torque, current_limit) <= R (rolling_resistance m g +
/// draft_force) / 2, with m the true mass (mass_scale × the nominal).
std::string checkMotorsCanMove(const MotorParams& motor, const RobotParams& robot, double mass_scale,
                               double rolling_resistance, double draft_force);

}  // namespace core
}  // namespace sowing_robot
