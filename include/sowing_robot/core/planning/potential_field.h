// Potential-field reference generator (thesis section 4.3, eqs 4.32-4.37, corrected; see
// docs/potential_field.md): a reference point with double-integrator dynamics is pulled onto a moving
// target (the sowing row) and pushed around obstacles.
//
//   p'' = p_d'' - alpha (p - p_d) - beta (p' - p_d') + mu(p),   mu = -k grad V_a + tangential term
//
// The integration runs on the error e = p - p_d, so with no obstacle in range e stays exactly zero and
// the reference IS the target.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/model/obstacle.h"

namespace sowing_robot {
namespace core {

/// Straight sowing row travelled at constant speed: p_d(t) = start + speed t (cos heading, sin heading).
struct RowLine {
  double x0 = 0.0, y0 = 3.0;  ///< position of the target at t = 0 [m] (thesis: x = t, y = 3)
  double heading = 0.0;       ///< direction of travel [rad]
  double speed = 1.0;         ///< v_r [m/s], > 0
  std::string validate() const;
};

/// A side of the direction of travel.
enum class AvoidSide {
  kLeft,   ///< pass with the obstacle on the right
  kRight,  ///< pass with the obstacle on the left
};

/// Defaults, ranges, units and meanings: potentialFieldTable().
struct PotentialFieldParams {
  PotentialFieldParams();
  double alpha;               ///< position gain alpha [1/s^2] (thesis: 4)
  double beta;                ///< damping of the velocity relative to the target, beta [1/s] (thesis: 16)
  double influence_distance;  ///< d: no repulsion beyond this clearance from the obstacle SURFACE [m]
  double gain;                ///< k: mu_radial = -k grad V_a [m^2/s^2], >= 0 (0 disables avoidance)
  double tangential_ratio;    ///< |tangential| / |radial| repulsion [-], >= 0
  /// true: when the reference enters an obstacle's influence zone it picks the side it is already on
  /// (offset from the centre of the obstacles whose zones it is in, along the left normal of travel,
  /// beyond +-side_band) and keeps it until it leaves the zone; obstacles with overlapping zones share
  /// the side. false: always avoid_side.
  bool nearest_side;
  /// Forced side (nearest_side = false) and tie-break inside the band: the on-line case goes this way.
  AvoidSide avoid_side;
  double side_band;  ///< half-width of the tie band [m], >= 0
  /// Below this fraction of d the clearance potential continues linearly (finite force, so a reference
  /// that starts inside an obstacle is pushed out instead of blowing up the integrator) [-], (0, 1).
  double core_fraction;
  double step;  ///< internal RK4 step h [s], (0, 1e-3]
  /// While both the reference and the target move slower than this [m/s], theta is held and
  /// omega = omega_dot = 0 (stops: a residual sideways creep must not turn the heading), >= 0.
  double heading_hold_speed;
  std::string validate() const;
};
/// alpha, beta, influence_distance, gain, tangential_ratio, nearest_side, avoid_side, side_band,
/// core_fraction, step, heading_hold_speed (keys without the `potential/` the nodes put before them).
const ParamTable<PotentialFieldParams>& potentialFieldTable();

/// Kinematic state of a target at one time; a, j are exact time derivatives of v, a.
struct TargetState {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();  ///< [m]
  Eigen::Vector2d v = Eigen::Vector2d::Zero();  ///< [m/s]
  Eigen::Vector2d a = Eigen::Vector2d::Zero();  ///< [m/s^2]
  Eigen::Vector2d j = Eigen::Vector2d::Zero();  ///< jerk [m/s^3]
  double heading = 0.0;                         ///< direction of travel [rad], defined also when the target is at rest
  bool tool_down = true;
};

/// A time-parameterised target; at(t) must be a pure function of t (t < 0 is treated as 0).
class TargetTrajectory {
 public:
  virtual ~TargetTrajectory() = default;
  virtual TargetState at(double t) const = 0;
  virtual std::unique_ptr<TargetTrajectory> clone() const = 0;
};

/// The target moving along a RowLine forever.
class LineTarget : public TargetTrajectory {
 public:
  explicit LineTarget(const RowLine& row);
  TargetState at(double t) const override;
  std::unique_ptr<TargetTrajectory> clone() const override { return std::make_unique<LineTarget>(*this); }
  const RowLine& row() const { return row_; }

 private:
  RowLine row_;
  Eigen::Vector2d u_;
};

/// Corrected thesis potential field (section 4.3) as a ReferenceSource.
///
/// * Clearance rho_i = |p - c_i| - r_i (distance to the obstacle surface); V_a = (1/2 (d/rho - 1))^2 for
///   rho <= d, 0 beyond (V_a and grad V_a are both zero at rho = d). Below core_fraction*d, V_a continues
///   linearly in rho.
/// * mu = sum_i f_i (n_i + s_i tangential_ratio R n_i), f_i = -k dV_a/drho >= 0, n_i = (p - c_i)/|p - c_i|,
///   R n = (n_y, -n_x) (n turned 90 deg clockwise) and s_i = +1 to pass obstacle i on the left of the
///   direction of travel, -1 on the right. The tangential part breaks the symmetric stall in front of
///   an obstacle on the line and always turns to the same, deterministic side. s_i is fixed when the
///   reference enters the zone (see nearest_side) and held while it stays in it; the force is zero on
///   the zone boundary, so choosing or releasing a side never makes a step.
/// * RK4 with a fixed step h on the grid t = n h; next(t) integrates to the last grid point <= t and
///   evaluates t by a partial RK4 step that is not kept, so the output depends only on t (and on when
///   setObstacles() was called).
/// * Output: theta = atan2(y', x'), v = |p'|, omega = (x'y'' - y'x'')/v^2, v_dot = p'.p''/v and an
///   analytic omega_dot from the jerk p''' = p_d''' + e''' with e''' = -alpha e' - beta e'' + J_mu p'
///   (J_mu the Jacobian of mu). Below 1e-4 m/s, or when the reference and the target are both slower
///   than heading_hold_speed, the last theta is held and omega = omega_dot = 0.
class PotentialField : public ReferenceSource {
 public:
  /// Straight row. Throws std::invalid_argument on invalid parameters or obstacles.
  PotentialField(const PotentialFieldParams& params, const RowLine& row = {}, std::vector<Obstacle> obstacles = {});
  /// Any target (e.g. a whole field with headland turns). Throws std::invalid_argument as above.
  PotentialField(const PotentialFieldParams& params, std::unique_ptr<TargetTrajectory> target,
                 std::vector<Obstacle> obstacles = {});
  PotentialField(const PotentialField& other);
  PotentialField& operator=(const PotentialField& other);
  PotentialField(PotentialField&&) = default;
  PotentialField& operator=(PotentialField&&) = default;

  /// Same params, target and current obstacle list, in the reset state.
  std::unique_ptr<ReferenceSource> clone() const override;

  /// Replace the obstacles (validated; throws std::invalid_argument). Takes effect from the current
  /// internal grid time on; the state is kept.
  void setObstacles(std::vector<Obstacle> obstacles);
  const std::vector<Obstacle>& obstacles() const { return obstacles_; }
  /// Replace the target (not empty; throws std::invalid_argument) keeping the reference point: the error
  /// state is re-based at the current grid time so the position and velocity there are unchanged, and
  /// the attraction then pulls the reference onto the new target. Used to re-plan at run time.
  void setTarget(std::unique_ptr<TargetTrajectory> target);
  /// The internal grid time the state is at [s].
  double gridTime() const { return static_cast<double>(steps_) * params_.step; }

  /// Sum over the obstacles of V_a(p) [-] (without the gain k).
  double repulsivePotential(const Eigen::Vector2d& p) const;
  /// Gradient of repulsivePotential() [1/m]; the radial repulsion is -k times this.
  Eigen::Vector2d repulsiveGradient(const Eigen::Vector2d& p) const;
  /// Full repulsive acceleration mu [m/s^2] (radial + tangential) for a target with the given state
  /// (with the sides currently held; an obstacle without one gets the side it would choose at p).
  Eigen::Vector2d repulsiveAcceleration(const Eigen::Vector2d& p, const TargetState& target) const;
  /// Smallest |p - c_i| - r_i over the obstacles [m]; +infinity without obstacles.
  double minObstacleClearance(const Eigen::Vector2d& p) const;

  const PotentialFieldParams& params() const { return params_; }
  /// Change the live-tunable gains alpha, beta, k (gain) and tangential_ratio; the state and the
  /// geometry are kept. Throws std::invalid_argument (and keeps the old gains) if they do not validate.
  void setGains(double alpha, double beta, double gain, double tangential_ratio);
  const TargetTrajectory& target() const { return *target_; }
  /// Reference position [m], velocity [m/s] and acceleration [m/s^2] of the last next() call.
  const Eigen::Vector2d& position() const { return out_p_; }
  const Eigen::Vector2d& velocity() const { return out_v_; }
  const Eigen::Vector2d& acceleration() const { return out_a_; }

 protected:
  /// Reference back on the target at t = 0 (position p_d(0), velocity p_d'(0)).
  void restart() override;
  /// Reference at t [s], t non-decreasing after reset(). tool_down is the target's.
  Reference evaluate(double t) override;

 private:
  struct ErrorState {
    Eigen::Vector2d e = Eigen::Vector2d::Zero(), ed = Eigen::Vector2d::Zero();
  };
  /// V_a'(rho) and V_a''(rho) for one clearance (zero beyond d).
  void clearanceDerivatives(double rho, double& dv, double& ddv) const;
  /// +1/-1: side to pass obstacle i at p (held one, or the one it would choose now).
  double sideFor(std::size_t i, const Eigen::Vector2d& p, const TargetState& target) const;
  /// Releases the sides of zones the reference at p has left and picks sides for zones it entered.
  void updateSides(const Eigen::Vector2d& p, const TargetState& target);
  /// mu at p; adds d mu/d p into *jacobian when given.
  Eigen::Vector2d mu(const Eigen::Vector2d& p, const TargetState& target, Eigen::Matrix2d* jacobian) const;
  /// e'' for an error state at time t with the target state tgt.
  Eigen::Vector2d errorAccel(const ErrorState& s, const TargetState& tgt) const;
  ErrorState rk4(const ErrorState& s, double t, double h) const;

  PotentialFieldParams params_;
  std::unique_ptr<TargetTrajectory> target_;
  std::vector<Obstacle> obstacles_;
  std::vector<signed char> sides_;  ///< held side per obstacle: +1 left, -1 right, 0 none (outside its zone)

  ErrorState state_;  ///< error state at the grid time steps_ * h
  long long steps_ = 0;
  double last_theta_ = 0.0;
  Eigen::Vector2d out_p_ = Eigen::Vector2d::Zero(), out_v_ = Eigen::Vector2d::Zero(), out_a_ = Eigen::Vector2d::Zero();
};

}  // namespace core
}  // namespace sowing_robot
