// The DDMR plant: Lagrangian dynamics in (v, w) with centre-of-mass offset d (eq 3.54), nonholonomic
// kinematics of the axle midpoint (eq 3.13) and the wheel angles, integrated with fixed-step RK4.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/model/motor.h"
#include "sowing_robot/core/model/robot_params.h"
#include "sowing_robot/core/model/torque_noise.h"

namespace sowing_robot {
namespace core {

/// Named indices into the plant state (no magic offsets).
enum StateIndex { X = 0, Y, THETA, V, OMEGA, PHI_R, PHI_L, STATE_SIZE };
using State = Eigen::Matrix<double, STATE_SIZE, 1>;

/// Everything the plant does to the ideal model: disturbance, noise and parameter mismatch.
/// Defaults, ranges, units and meanings: disturbanceTable().
struct PlantDisturbance {
  PlantDisturbance();
  bool sinusoidal;       ///< add td_R = A sin(w t), td_L = A cos(w t) to the wheel torques (Fig 5.9)
  double amplitude;      ///< A [N·m]
  double frequency;      ///< w [rad/s]
  double noise_std;      ///< std of Gaussian wheel-torque noise, held over one step [N·m]; 0 = off
  std::uint64_t seed;    ///< seed of the noise generator
  double mass_scale;     ///< true m0 and mc·d are this times the nominal (1 = no mismatch)
  double inertia_scale;  ///< true I0 is this times the nominal (1 = no mismatch)

  std::string validate() const;
};
/// disturbance/{sinusoidal, amplitude, frequency}, noise/{std, seed}, mismatch/{mass_scale, inertia_scale}.
const ParamTable<PlantDisturbance>& disturbanceTable();

/// Fixed-step RK4 simulation of the DDMR. The pose (x, y, theta) is that of the axle midpoint
/// (REP-105 base_link); the centre of mass sits d ahead of it.
class Plant {
 public:
  /// Throws std::invalid_argument when either does not validate.
  Plant(const RobotParams& nominal, const PlantDisturbance& disturbance);

  /// Start again at time t with the given state (noise generator re-seeded). Throws
  /// std::invalid_argument for a non-finite state or time.
  void reset(const State& initial, double t = 0.0);

  /// Advance by dt [s] with the commanded wheel torques [N·m], held constant over the step. Returns
  /// false, leaving the state, the time and the noise generator untouched, when a torque is not finite
  /// or dt is not a finite positive number: bad input never reaches the integrator.
  bool step(double tau_right, double tau_left, double dt);

  /// Time derivative of the state for the *applied* torques (commands + disturbance already added).
  State derivative(const State& s, double applied_right, double applied_left) const;

  /// Sinusoidal wheel-torque disturbance at time t [N·m] (zero when switched off).
  void sinusoidalDisturbance(double t, double& right, double& left) const;

  /// The drive motors (motor.h): from the next step on, each wheel's command passes through its motor
  /// (disabled: unchanged). Throws std::invalid_argument when the parameters do not validate.
  void setMotor(const MotorParams& motor);
  /// The torque [N·m] the right (0) / left (1) motor applied over the last step, before disturbance and noise.
  double appliedTorque(int wheel) const { return applied_[wheel]; }

  const State& state() const { return state_; }
  double time() const { return time_; }
  /// Physical parameters the plant really has (nominal scaled by the mismatch).
  double trueM0() const { return m0_; }
  double trueI0() const { return i0_; }

  /// Position of the centre of mass (eq 3.26: x_c = x + d cos theta, y_c = y + d sin theta).
  Eigen::Vector2d centreOfMass() const;

 private:
  RobotParams nominal_;
  PlantDisturbance disturbance_;
  State derivativeWithHeading(const State& s, double cos_th, double sin_th, double applied_right,
                              double applied_left) const;
  void disturbanceAt(double t, double& right, double& left);  // sinusoidalDisturbance, memoised
  bool stepWithHeading(double tau_right, double tau_left, double dt, double cos0, double sin0);
  void drawNoise(double& right, double& left);  // the step's torque noise (0, 0 when off)
  void addIncrement(double x, double y, double theta, double v, double omega, double phi_r, double phi_l, double dt);

  double m0_, i0_, mcd_;  // true effective inertias and the coupling mc·d
  State state_ = State::Zero();
  double time_ = 0.0;
  TorqueNoise noise_;
  WheelMotor motor_[2];
  double applied_[2] = {0.0, 0.0};  // std::normal_distribution<double> over std::mt19937_64, to the bit
  // Last disturbance evaluated (NaN time: none yet). Never compares equal to NaN, so reset() clears it.
  double cached_disturbance_time_ = std::numeric_limits<double>::quiet_NaN();
  double cached_disturbance_right_ = 0.0, cached_disturbance_left_ = 0.0;
};

}  // namespace core
}  // namespace sowing_robot
