// Pure pursuit and nav2's Regulated Pure Pursuit (RPP) for a DDMR, as the outer (kinematic) controller
// in Kanayama's place: reference + measured pose and velocities in, VelocityCommand (v, omega and their
// desired time derivatives) out. Baselines for the benchmark: what users run today.
//
// The lookahead point ("carrot"). nav2 takes it on a path at distance L from the robot; here the
// reference is a trajectory given one time at a time by a stateful source (the potential field cannot
// be asked ahead), so the carrot is the current reference pose carried forward by arc length L along
// the reference's instantaneous circle (curvature omega_r / v_r). For lines and arcs this is exactly the
// reference at t + L / v_r; for curved rows it is a first-order extrapolation. When the robot is on the
// reference it is nav2's carrot.
//
// Curvature kappa = 2 y / d^2 with (x, y) the carrot in the robot frame and d its distance (nav2's
// code uses the carrot distance; d = L on the path, the textbook kappa = 2y/L^2), omega = v kappa.
//
// Speed: nav2 drives at desired_linear_vel; here that is the reference speed v_r, plus an optional
// along-track feedback k_along * xe (not in nav2, default 0 = nav2) so that a trajectory, not only a
// path, can be tracked. RPP's curvature heuristic then scales v by r / r_min when the turning radius
// r = 1/|kappa| is below r_min, not below the minimum regulated speed (nor above the unregulated v).
// nav2's cost-based and approach-to-goal scaling need a costmap and a goal and are not modelled; nor
// is rotate-to-heading.
//
// Desired accelerations are analytic, like Kanayama's: the time derivatives of the law along the
// robot's measured motion (v, omega) and a carrot moving at v_r along its circle; the lookahead is held
// constant in the derivative (velocity-scaled mode drops dL/dt) and the reference's own v_dot enters the
// speed term. No finite differences, so no dt and no filter lag.
#pragma once

#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"

namespace sowing_robot {
namespace core {

/// Defaults (nav2's), ranges and units: purePursuitTable().
struct PurePursuitParams {
  PurePursuitParams();
  double lookahead_dist;      ///< L when not velocity-scaled [m]
  double min_lookahead_dist;  ///< [m]
  double max_lookahead_dist;  ///< [m]
  double lookahead_time;      ///< velocity-scaled L = |v| t, clamped to [min, max] [s]
  bool use_velocity_scaled_lookahead_dist;
  double min_radius;  ///< regulated_linear_scaling_min_radius [m] (RPP only)
  double min_speed;   ///< regulated_linear_scaling_min_speed [m/s] (RPP only)
  double k_along;     ///< along-track speed feedback [1/s]; 0 = nav2's constant desired speed

  /// Ranges (the table), then min <= L <= max.
  std::string validate() const;
};
/// lookahead_dist, min_lookahead_dist, max_lookahead_dist, lookahead_time,
/// use_velocity_scaled_lookahead_dist, regulated_linear_scaling_min_radius,
/// regulated_linear_scaling_min_speed, k_along.
const ParamTable<PurePursuitParams>& purePursuitTable();

class PurePursuit {
 public:
  /// regulated = true: RPP's curvature heuristic on the speed; false: plain pure pursuit. Throws
  /// std::invalid_argument when the parameters do not validate.
  explicit PurePursuit(const PurePursuitParams& params = {}, bool regulated = true);

  /// One command. A non-finite input gives the stop command (all zero), as Kanayama::compute; a stop
  /// hold in the reference (ref.stop) gives holdCommand().
  VelocityCommand compute(const Reference& ref, const Pose2D& actual, double v, double omega) const;

  /// The lookahead distance in use at measured speed v.
  double lookahead(double v) const;
  /// The carrot for `ref` at lookahead L (world frame; theta = the reference heading there).
  static Pose2D carrot(const Reference& ref, double L);

  bool regulated() const { return regulated_; }
  const PurePursuitParams& params() const { return params_; }
  /// Throws std::invalid_argument (parameters kept) when p does not validate.
  void setParams(const PurePursuitParams& p);

 private:
  PurePursuitParams params_;
  bool regulated_;
};

}  // namespace core
}  // namespace sowing_robot
