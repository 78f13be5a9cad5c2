// Wheel-velocity PID with feedforward and anti-windup, the inner (torque) controller in the
// sliding-mode controller's place: what a ros_control user runs (diff_drive_controller turns (v, omega)
// into wheel speeds, a motor driver closes a PID on each wheel's speed). A baseline for the benchmark.
//
// Wheel speed targets w_d = (v_d +- L omega_d) / R (right +, left -), measured w the same from the
// measured v, omega. Per wheel: tau = ff + kp e + ki int(e) + kd d/dt(-w) (derivative on the
// measurement: no kick on a step of the target), clipped at +-max_torque (clipping reported).
// Feedforward: the nominal rigid-body inertia for the desired accelerations, the same model terms the
// sliding-mode controller uses (eq 4.10): tau_r + tau_l = m0 R v_dot_d, tau_r - tau_l = (I0 R / L)
// omega_dot_d, scaled by `feedforward` (0 = none, 1 = the nominal model).
// Anti-windup (on by default): the integral term ki int(e) is clamped to +-max_torque, and the integral
// is not advanced in a period whose output saturates with the error pushing further into the limit
// (conditional integration). Off, the integral runs free (as a naive driver's would).
#pragma once

#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/model/robot_params.h"

namespace sowing_robot {
namespace core {

/// Defaults, ranges and units: wheelPidTable().
struct WheelPidParams {
  WheelPidParams();
  double kp;           ///< [N·m·s/rad]
  double ki;           ///< [N·m/rad]
  double kd;           ///< [N·m·s^2/rad]
  double feedforward;  ///< scale of the nominal inertia feedforward (0 = none, 1 = nominal model)
  double max_torque;   ///< per-wheel motor limit [N·m]
  bool anti_windup;

  std::string validate() const;
};
/// kp, ki, kd, feedforward, max_torque, anti_windup.
const ParamTable<WheelPidParams>& wheelPidTable();

/// What one control update produced, for logging, plots and tests.
struct WheelPidOutput {
  WheelTorques torques;
  double e_right = 0.0, e_left = 0.0;  ///< wheel speed errors, target minus measured [rad/s]
  double i_right = 0.0, i_left = 0.0;  ///< integral terms ki int(e) [N·m]
  double u_right = 0.0, u_left = 0.0;  ///< before clipping [N·m]
  bool saturated = false;
  bool rejected = false;  ///< the input was not finite: the previous output, held
  bool holding = false;   ///< a stop hold: integrals frozen, zero torques (as SlidingModeOutput::holding)
};

class WheelPid {
 public:
  /// `nominal` gives R, L, m0 and I0 (the feedforward's model). Throws std::invalid_argument when
  /// either does not validate.
  WheelPid(const WheelPidParams& params, const RobotParams& nominal);

  /// Integrals, derivative memory and the held output to zero.
  void reset();

  /// One control period of length dt [s]. A non-finite input (or dt not a finite positive number) is
  /// rejected: integrals and derivative memory untouched, the previous output returned again with
  /// rejected = true (zero torques before the first accepted period). With desired.hold the integrals stay
  /// as they are and the output is zero torque with holding = true (the standstill hold brakes); the
  /// derivative's memory follows the wheels, so the first period after the hold has no kick.
  WheelPidOutput update(const VelocityCommand& desired, double v, double omega, double dt);

  const WheelPidParams& params() const { return params_; }
  /// Change gains live (integrals kept). Throws std::invalid_argument, keeping the old parameters.
  void setParams(const WheelPidParams& params);
  /// What a layer between this controller and the motors (the traction control) sent for the last
  /// output: where it held a wheel's torque below (above) the output, the next update does not integrate
  /// that wheel's error further upwards (downwards), as with its own max_torque (anti-windup on). Cleared
  /// by that update.
  void heldBack(const WheelTorques& sent);
  /// The feedforward's model parameters (what the loop reports as the "estimates").
  double m0() const { return m0_; }
  double i0() const { return i0_; }

 private:
  struct Wheel {
    double integral = 0.0;  ///< int e dt [rad]
    double last_w = 0.0;    ///< measured speed of the previous accepted period
    bool has_last = false;
    int held = 0;  ///< +1: a layer held the last output down, -1: up (heldBack), 0: not
  };
  /// One wheel's PID; returns the unclipped output and updates the wheel's memory.
  double wheel(Wheel& s, double w_d, double w, double ff, double dt, double& e, double& i_term) const;

  WheelPidParams params_;
  double R_, L_, m0_, i0_;
  Wheel right_, left_;
  WheelPidOutput last_output_;
};

}  // namespace core
}  // namespace sowing_robot
