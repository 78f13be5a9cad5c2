// Wheel–soil traction for the DDMR: an opt-in plant in which each drive wheel has
// its own spin state and pushes the body through the longitudinal slip of its contact patch. The
// no-slip Plant (plant.h) is untouched; with grip and slip stiffness large this model tends to it.
//
// Model (body frame, axle midpoint; right wheel at +L, left at -L, caster at caster_x ahead):
//   contact speed   u_i = v ± L w                 slip velocity  s_i = R Ω_i − u_i
//   slip ratio      κ_i = s_i / max(|u_i|, |R Ω_i|, slip_speed_floor)        (|κ| <= 2)
//   ground force    F_i = N_i μ(κ_i)               (friction curve: tractionFriction(); |F_i| <= mu_peak N_i)
//   wheel spin      Iw Ω_i' = τ_i − R F_i
//   body            m_b v' − mc d w² = F_R + F_L + F_rr,x
//                   I_b w' + mc d w v = L (F_R − F_L) + M_rr
// with m_b = m0 − 2 Iw/R² and I_b = I0 − 2 L² Iw/R² (m0, I0 of eq 3.55 scaled by the plant's mismatch),
// so that the no-slip limit Ω_i = u_i / R gives back eq 3.54 exactly. Lateral slip is left out: the
// wheels keep the thesis's nonholonomic constraint (no sideways motion of the axle).
// Normal loads are static: moments about the axle of the weight (COM mc d / m ahead of it) and the
// caster reaction give N_caster = mc g d / caster_x and N_R = N_L = (m g − N_caster) / 2 (clamped to
// [0, m g]: this plant does not tip over). No load transfer under acceleration (no COM height in the
// robot's parameters). Rolling resistance: rolling_resistance × N at each wheel and at the caster,
// against the contact point's motion (regularised linearly below slip_speed_floor), evaluated once per
// step (it is not stiff).
//
// Integration: `substeps` sub-steps per step(), first order. Each sub-step is linearly implicit
// (Rosenbrock–Euler) in the two slip velocities: the friction forces are linearised in s_i at the
// sub-step's start (up to the friction peak with the larger of the curve's tangent and secant, past it
// not at all) and the coupled 2×2 system (wheel spin + body translation + yaw) is solved for their
// change, so the stiff slip mode (rate ~R² N μ' / (Iw D), 10^3..10^7 1/s) is damped at any step size.
// Torques and rolling resistance are explicit; the centre-of-mass coupling is an exact rotation of
// (√m v, √I w) that does no work (as in the ODE). Pose and wheel angles use the mean of the old and new
// velocities (heading at the sub-step's midpoint). The sinusoidal disturbance is taken at each
// sub-step's midpoint, the torque noise held over the step (as Plant). Errors against a 1 µs reference
// and the no-slip limit: test/core/model/test_traction.cpp.
//
// Soil patches (setSoil, soil_map.h): at the start of every step each wheel's contact point (the axle
// midpoint ± L sideways; right wheel at −L in base_link, URDF) and the caster's are looked up; a wheel
// in a patch uses its mu_peak, mu_slide and rolling_resistance (the slip curve's shape, slip_peak and
// slip_stiffness, stays the field's), elsewhere the traction/ values.
// The tool's draft (setToolDown, setToolDepth; toolDraft()): while the tool is down, a force of magnitude
// D acts at the tool point (xt, yt) in base_link against that point's velocity (v − w yt, w xt),
// regularised linearly below slip_speed_floor and semi-implicit, so that a draft far beyond the motors
// stays stable (at the price of a relative shortfall dt D / (m v): 7e-4 for 10 N at 1 m/s). As for the
// caster, its generalised forces under the nonholonomic constraint are F_x on v and xt F_y − yt F_x on
// w: a tool off the axle line (yt ≠ 0) turns the robot towards its side, one behind the axle (xt < 0)
// damps the yaw. The sideways part is held by the wheels (no lateral slip, also on ice). Evaluated
// once per step, as the rolling resistance.
// Its magnitude follows the draft law of ASABE D497 (Agricultural Machinery Management Data, section 4.1;
// Harrigan & Rotz, Applied Engineering in Agriculture 11(6), 1995), D = F_i (A + B S + C S²) W T, with F_i the
// soil's texture factor, A, B, C the machine's constants, S the speed, W the width, T the depth. For one
// opener of fixed width it is calibrated on traction/draft_force D0, the draft at the drill's nominal working
// depth T0 (draft_depth) and speed S0 (draft_speed) on the field's soil:
//   D(T, S) = D0 · F · (T / T0) · (1 + b S + c S²) / (1 + b S0 + c S0²),   b = B/A, c = C/A,
// F the patch's draft_factor under the tool point (1 on the field's soil), S the tool point's speed. At T0 and
// S0 it is D0 exactly, so a run that keeps the drill at its nominal depth (no depth control) has today's draft.
// The speed terms default to 0: D497 lists seeding implements (planters, drills) with a per-row constant
// (B = C = 0); a tine opener that tills its slot has speed terms (D497's tillage tines) to be set here.

#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/model/motor.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/model/robot_params.h"
#include "sowing_robot/core/model/soil_map.h"

namespace sowing_robot {
namespace core {

/// Ground and traction parameters. Defaults, ranges, units and meanings: tractionTable().
struct TractionParams {
  TractionParams();
  bool enabled;               ///< use the traction plant instead of the no-slip Plant (read by the wrappers)
  double mu_peak;             ///< peak friction coefficient (at slip_peak)
  double mu_slide;            ///< friction coefficient in full slide (|κ| >= 1)
  double slip_peak;           ///< slip ratio of the peak
  double slip_stiffness;      ///< dμ/dκ at κ = 0 [1/unit slip]
  double rolling_resistance;  ///< rolling-resistance coefficient (force / normal load)
  double slip_speed_floor;    ///< [m/s] smallest speed the slip ratio is divided by
  double caster_x;            ///< [m] caster contact ahead of the axle (URDF caster_joint x)
  int substeps;               ///< integration sub-steps per plant step
  double draft_force;  ///< [N] the seed drill tool's draft while it is down, at draft_depth and draft_speed (0: none)
  double draft_depth;  ///< [m] the drill's nominal working depth (the depth draft_force is for)
  double draft_speed;  ///< [m/s] the speed draft_force is for
  double draft_speed_linear;     ///< [s/m] D497's B/A: the draft's linear rise with speed (0: none)
  double draft_speed_quadratic;  ///< [s²/m²] D497's C/A: its quadratic rise with speed (0: none)
  double tool_depth_min;         ///< [m] the drill's mechanical depth range: shallowest it can be set to
  double tool_depth_max;         ///< [m] deepest it can be set to

  /// checkRanges() plus the cross rules: mu_slide <= mu_peak, slip_stiffness >= mu_peak / slip_peak,
  /// tool_depth_min < tool_depth_max, draft_depth within [tool_depth_min, tool_depth_max].
  std::string validate() const;
};
/// traction/{enabled, mu_peak, mu_slide, slip_peak, slip_stiffness, rolling_resistance,
/// slip_speed_floor, caster_x, substeps, draft_force, draft_depth, draft_speed, draft_speed_linear,
/// draft_speed_quadratic, tool_depth_min, tool_depth_max}.
const ParamTable<TractionParams>& tractionTable();

/// The tool's draft [N] at `depth` [m] and the tool point's `speed` [m/s] on a soil of draft factor
/// `soil_factor` (the file comment's law; draft_force exactly at draft_depth, draft_speed, factor 1).
double toolDraft(const TractionParams& p, double depth, double speed, double soil_factor = 1.0);

/// Friction coefficient μ(κ) of the curve (odd in κ): a rational rise μ_p g(|κ|/κ_p),
/// g(x) = a x / ((1 − x)² + a x), a = K κ_p / μ_p (slope K at 0, peak μ_p with zero slope at κ_p), then
/// a smoothstep fall to μ_s at |κ| = 1, μ_s beyond. `slope` (if given) gets dμ/dκ.
double tractionFriction(const TractionParams& p, double kappa, double* slope = nullptr);

/// The friction curve of tractionFriction() with its constants worked out once.
struct FrictionCurve {
  explicit FrictionCurve(const TractionParams& p)
      : mu_p(p.mu_peak),
        mu_s(p.mu_slide),
        kp(p.slip_peak),
        inv_kp(1.0 / p.slip_peak),
        a(p.mu_peak > 0.0 ? p.slip_stiffness * p.slip_peak / p.mu_peak : 0.0),
        inv_fall(1.0 / (1.0 - p.slip_peak)) {}

  /// μ(|κ|) >= 0 for ak = |κ|; slope gets dμ/d|κ|.
  double eval(double ak, double& slope) const {
    if (ak <= kp) {
      if (mu_p <= 0.0) {
        slope = 0.0;
        return 0.0;
      }
      const double x = ak * inv_kp, one_minus = 1.0 - x;
      const double den = one_minus * one_minus + a * x, inv_den = 1.0 / den;
      slope = mu_p * a * (1.0 - x * x) * inv_den * inv_den * inv_kp;
      return mu_p * a * x * inv_den;
    }
    if (ak < 1.0) {
      const double y = (ak - kp) * inv_fall, drop = mu_p - mu_s;
      slope = -drop * 6.0 * y * (1.0 - y) * inv_fall;
      return mu_p - drop * y * y * (3.0 - 2.0 * y);
    }
    slope = 0.0;
    return mu_s;
  }

  /// μ(|κ|) as eval(), with `jacobian` the slope the integrator linearises with: up to the peak the
  /// larger of the tangent and the secant μ/|κ|, past it 0 (see TractionPlant::substep).
  double evalForIntegration(double ak, double& jacobian) const {
    if (ak <= kp && mu_p > 0.0) {
      const double x = ak * inv_kp, one_minus = 1.0 - x;
      const double den = one_minus * one_minus + a * x, inv_den = 1.0 / den;
      const double secant = mu_p * a * inv_kp * inv_den;  // μ / |κ|, finite at 0 (= K there)
      jacobian = std::max(secant * (1.0 - x * x) * inv_den, secant);
      return secant * ak;
    }
    double unused;
    jacobian = 0.0;
    return eval(ak, unused);
  }

  double mu_p, mu_s, kp, inv_kp, a, inv_fall;
};

/// Static normal loads [N] of the right and left drive wheels and the caster (see the file comment).
struct NormalLoads {
  double right = 0.0, left = 0.0, caster = 0.0;
};
NormalLoads staticNormalLoads(const RobotParams& robot, double mass_scale, double caster_x);

/// What a soil offers the drive wheels against what driving on it takes, on level ground at steady speed
/// [N]: the friction at the peak and in full slide of both drive wheels' static loads, against the rolling
/// resistance of every contact (m g in all) plus the tool's draft. peak < needed: no grip to be had.
struct GripBudget {
  double peak = 0.0, slide = 0.0, needed = 0.0;
  double margin() const { return peak - needed; }
};
GripBudget gripBudget(const RobotParams& robot, double mass_scale, const TractionParams& traction, double mu_peak,
                      double mu_slide, double rolling_resistance);
/// The same with the tool's draft given [N] (gripBudget above takes traction.draft_force).
GripBudget gripBudget(const RobotParams& robot, double mass_scale, const TractionParams& traction, double mu_peak,
                      double mu_slide, double rolling_resistance, double draft);

/// The field check before a run: whether a soil's grip budget carries the drill's draft at a given depth (the
/// agronomic band's shallowest, the least a depth control can pull) and the nominal speed (draft_speed).
struct DraftCheck {
  int patch = -1;       ///< soil patch index; -1: the field's own soil
  GripBudget budget;    ///< with `draft` in needed
  double draft = 0.0;   ///< [N] the draft at `depth` and draft_speed on this soil
  double depth = 0.0;   ///< [m] the depth checked (clamped to the mechanical range)
  bool carried = true;  ///< budget.peak >= budget.needed: the wheels can pull the drill straight at the peak
  std::string why;      ///< one line: the soil, its budget, the draft, the verdict
};
/// The field's soil first, then each patch in order. Nothing to check (draft_force 0): an empty list.
std::vector<DraftCheck> checkFieldDraft(const RobotParams& robot, double mass_scale, const TractionParams& traction,
                                        const std::vector<SoilPatch>& patches, double depth);
/// One line per soil that cannot carry the drill (checkFieldDraft), or "" when every one can.
std::string fieldDraftWarnings(const std::vector<DraftCheck>& checks);
/// The grip budget of the soil at `where` (the patch there, else the field's soil) as one line: "soil patch 2 grip
/// budget: peak traction 7.4 N (sliding 5.9 N) against 24.1 N needed". What a simulation adds to a no-traction
/// report (the robot itself cannot know the soil's grip): the in-process loop's and plant_sim's.
std::string gripDiagnosis(const RobotParams& robot, double mass_scale, const TractionParams& traction,
                          const SoilMap& soil, const Eigen::Vector2d& where);

enum Wheel { RIGHT = 0, LEFT = 1 };
constexpr int kCaster = 2;  ///< contact index of the caster (patchUnder)

/// The DDMR with wheel slip. step()/state()/time() as Plant; state() holds the same seven entries
/// (PHI_R, PHI_L are the wheels' true spin angles, what an encoder would count).
class TractionPlant {
 public:
  /// Throws std::invalid_argument when a parameter set does not validate.
  TractionPlant(const RobotParams& nominal, const PlantDisturbance& disturbance, const TractionParams& traction);

  /// Start again at time t; the wheels start rolling without slip (Ω_i = u_i / R). Throws
  /// std::invalid_argument for a non-finite state or time.
  void reset(const State& initial, double t = 0.0);

  /// Advance by dt [s] with the commanded wheel torques [N·m] held over the step (plus the disturbance,
  /// as in Plant). Returns false, changing nothing, for a non-finite torque or dt <= 0.
  bool step(double tau_right, double tau_left, double dt);

  /// The drive motors (motor.h), evaluated at every sub-step at the wheel's own spin rate (a spinning
  /// wheel loses torque). Throws std::invalid_argument when the parameters do not validate.
  void setMotor(const MotorParams& motor);
  /// The torque [N·m] the right / left motor applied in the last sub-step, before disturbance and noise.
  double appliedTorque(Wheel w) const { return applied_[w]; }

  const State& state() const { return state_; }
  double time() const { return time_; }
  /// Wheel spin rates Ω [rad/s].
  double wheelRate(Wheel w) const { return wheel_rate_[w]; }
  /// Slip ratio κ and ground force F [N] of the last sub-step.
  double slipRatio(Wheel w) const { return slip_[w]; }
  double groundForce(Wheel w) const { return force_[w]; }
  const NormalLoads& normalLoads() const { return loads_; }
  /// Override the normal loads [N] (a wheel in the air: 0; later: terrain). Throws for negative/NaN.
  void setNormalLoads(const NormalLoads& loads);
  /// Soil patches (validated by SoilMap); the rest of the field keeps the traction parameters. Throws
  /// std::invalid_argument when a patch's grip does not fit the slip curve (slip_stiffness >=
  /// mu_peak / slip_peak).
  void setSoil(const SoilMap& soil);
  const SoilMap& soil() const { return soil_; }
  /// Patch index (-1: default soil) under each wheel and the caster, as of the last step's start.
  int patchUnder(int contact) const { return ground_[contact] - 1; }
  /// The tool point in base_link [m] (URDF tool_link; default (-0.45, 0)).
  void setToolPoint(const Eigen::Vector2d& p) { tool_ = p; }
  /// Tool down: the draft acts from the next step on (the caller applies the seed drill's rule).
  void setToolDown(bool down) { tool_down_ = down; }
  bool toolDown() const { return tool_down_; }
  /// The drill's working depth [m] from the next step on, clamped to the mechanical range
  /// (tool_depth_min..tool_depth_max); a non-finite depth is refused (false, unchanged). reset() does not
  /// change it; it starts at traction/draft_depth.
  bool setToolDepth(double depth);
  double toolDepth() const { return tool_depth_; }
  /// Patch index (-1: default soil) under the tool point, as of the last step's start (draft_force > 0).
  int patchUnderTool() const { return ground_tool_ - 1; }
  /// The draft's generalised force on v [N] and moment on w [N·m] of the last step (0 with the tool up).
  double draftForce() const { return draft_f_; }
  double draftMoment() const { return draft_m_; }
  /// Kinetic energy [J]: body translation and yaw plus both wheels' spin.
  double kineticEnergy() const;
  double bodyMass() const { return m_b_; }
  double bodyYawInertia() const { return i_b_; }

 private:
  void rollingResistance(double& force, double& moment) const;
  /// The draft's generalised force and moment for a step of dt (see the file comment).
  void draft(double dt, double& force, double& moment) const;
  /// ground_ of the wheels' and the caster's contact points (soil patches).
  void locateContacts();
  void substep(double tau_r, double tau_l, double rr_force, double rr_moment, double h);

  RobotParams nominal_;
  PlantDisturbance disturbance_;
  TractionParams traction_;
  std::vector<FrictionCurve> curves_;  // [0]: the traction parameters, [1 + i]: patch i
  std::vector<double> rr_;             // rolling resistance, indexed as curves_
  std::vector<double> draft_factor_;   // the drill's draft factor, indexed as curves_ ([0]: 1)
  SoilMap soil_;
  int ground_[3] = {0, 0, 0};  // curves_ index under the right wheel, the left wheel, the caster
  Eigen::Vector2d tool_{-0.45, 0.0};
  bool tool_down_ = false;
  double tool_depth_;
  int ground_tool_ = 0;  // curves_ index under the tool point
  double draft_f_ = 0.0, draft_m_ = 0.0;
  double m_b_, i_b_, mcd_;
  double sqrt_m_, sqrt_i_, inv_sqrt_mi_, inv_sqrt_m_, inv_sqrt_i_;
  double inv_m_, inv_i_, inv_iw_, inv_floor_;
  double slip_a_, slip_b_;  // A = R²/Iw + 1/m + L²/I and B = 1/m − L²/I of the slip system
  NormalLoads loads_;
  State state_ = State::Zero();
  double wheel_rate_[2] = {0.0, 0.0};
  double slip_[2] = {0.0, 0.0}, force_[2] = {0.0, 0.0};
  double time_ = 0.0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_{0.0, 1.0};
  WheelMotor motor_[2];
  double applied_[2] = {0.0, 0.0};
};

}  // namespace core
}  // namespace sowing_robot
