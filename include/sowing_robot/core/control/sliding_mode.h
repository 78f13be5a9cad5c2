// Integral terminal sliding-mode wheel-torque controller (eqs 4.7-4.22): adaptive (ATSMC) or with
// fixed nominal parameters (TSMC, the thesis's baseline).
#pragma once

#include <string>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/control/switching.h"
#include "sowing_robot/core/model/robot_params.h"

namespace sowing_robot {
namespace core {

/// Real power x^(num/den) for an odd den, i.e. the real root: sign(x)^num |x|^(num/den).
double realPower(double x, int num, int den);

/// Which estimate the adaptation rates act on (README deviation 8, docs/deviations.md).
///   mass_inertia (default): the rates multiply S·phi in the laws of m0_hat and I0_hat themselves;
///   eq_4_22: the literal eq 4.22, the rates act on gamma_hat = m0_hat R and alpha_hat = I0_hat R / L,
///            so m0_hat moves 1/R (~10.5x) and I0_hat L/R times as fast for the same rate.
enum class Adaptation { mass_inertia, eq_4_22 };

/// Defaults, ranges, units and meanings: slidingModeTable().
struct SlidingModeParams {
  SlidingModeParams();
  bool adaptive;                  ///< true: ATSMC (eq 4.22 with projection); false: TSMC (fixed nominal)
  int p, q;                       ///< terminal exponent p/q, both odd, 1 < p/q < 2
  double beta_v, beta_omega;      ///< surface gains beta per channel (not given in the thesis)
  double k1, k2;                  ///< feedback gains K1 [N·m·s/m], K2 [N·m·s/rad]
  double eta1, eta2;              ///< switching gains [N·m]
  double rate_m, rate_i;          ///< adaptation rates of m0_hat and I0_hat (Table 5.3 gamma1/2)
  Adaptation adaptation;          ///< what rate_m, rate_i act on (default mass_inertia)
  double m0_min, m0_max;          ///< projection bounds on m0_hat [kg]
  double i0_min, i0_max;          ///< projection bounds on I0_hat [kg·m^2]
  double m0_initial, i0_initial;  ///< initial/nominal estimates; 0 means "from the URDF"
  double max_torque;              ///< per-wheel motor limit [N·m]
  SwitchFunction switching;

  /// Ranges (the table), then p/q odd with 1 < p/q < 2, min < max, initial estimates within the bounds.
  std::string validate() const;
};
/// mode, p, q, beta_v, beta_omega, k1, k2, eta1, eta2, rate_m, rate_i, adaptation, m0_min, m0_max, i0_min, i0_max,
/// m0_initial, i0_initial, max_torque, switching, switch_width.
const ParamTable<SlidingModeParams>& slidingModeTable();

/// What one control update produced, for logging and plots.
struct SlidingModeOutput {
  WheelTorques torques;
  double e_v = 0.0, e_omega = 0.0;  ///< desired minus measured
  double s_v = 0.0, s_omega = 0.0;  ///< sliding variables S1, S2
  double u1 = 0.0, u2 = 0.0;        ///< before saturation
  bool saturated = false;
  bool rejected = false;  ///< the input was not finite: the previous output, held (see update())
  /// A stop hold (VelocityCommand::hold): the controller's states are frozen and its torques are 0; the
  /// standstill hold (standstill_hold.h), which measures the wheels, sets the torques sent.
  bool holding = false;
};

class SlidingModeController {
 public:
  /// `nominal` gives R, L and (where the params leave them <= 0) the initial m0, I0 estimates. Throws
  /// std::invalid_argument when either does not validate.
  SlidingModeController(const SlidingModeParams& params, const RobotParams& nominal);

  /// Zero the integrals and return the estimates to their initial values (and the held output to zero).
  void reset();
  /// Zero only the sliding-surface integrals (estimates kept): a clean restart after an input gap.
  void resetSurfaces() { linear_ = angular_ = Channel{}; }

  /// One control period of length dt [s]. A non-finite input (or dt not a finite positive number) is
  /// rejected: integrals and adaptive estimates are untouched and the previous output is returned
  /// again with rejected = true (zero torques before the first accepted period). With desired.hold the
  /// integrals and estimates stay as they are (nothing winds up at rest) and the output is zero torque with
  /// holding = true; the first period without it carries on from them.
  SlidingModeOutput update(const VelocityCommand& desired, double v, double omega, double dt);

  double m0Hat() const { return m0_hat_; }
  double i0Hat() const { return i0_hat_; }
  const SlidingModeParams& params() const { return params_; }
  /// Change gains live (integrals and estimates are kept; estimates clamped into new bounds). Throws
  /// std::invalid_argument, keeping the old parameters, when params do not validate.
  void setParams(const SlidingModeParams& params);
  /// What a layer between this controller and the motors (the traction control) sent for the last
  /// output: a channel (v: u1 = tau_r + tau_l, omega: u2 = tau_r - tau_l) whose error pushes against a
  /// wheel torque that was held back does not advance its sliding-surface integral or its adaptive
  /// estimate in the next update (anti-windup; this controller has none at max_torque). Cleared by that update.
  void heldBack(const WheelTorques& sent);

 private:
  struct Channel {
    double integral = 0.0;
    int held = 0;  ///< +1: pushing this channel up was held back, -1: down, 2: both (heldBack), 0: neither
  };
  /// Whether the channel's error e pushes against what a layer held back (and clears the mark).
  static bool heldAgainst(Channel& c, double e);
  /// S and phi = x_dot_d + beta (p/q) e (int e)^(p/q-1) for one channel; updates its integral (not while held).
  void surface(Channel& c, double e, double xd_dot, double beta, double dt, bool held, double& s, double& phi) const;

  SlidingModeParams params_;
  double R_, L_;
  double m0_initial_, i0_initial_;
  double m0_hat_, i0_hat_;
  double rate_m_, rate_i_;  ///< the rates of m0_hat and I0_hat themselves (params_ scaled by `adaptation`)
  double exponent_;         ///< p / q (set with params_: a division the surface needed twice every period)
  Channel linear_, angular_;
  SlidingModeOutput last_output_;  ///< held on a rejected input
};

}  // namespace core
}  // namespace sowing_robot
