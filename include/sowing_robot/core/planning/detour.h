// Planned detours around obstacles on straight rows: the obstacles are inflated by the
// robot's footprint plus a safety margin, obstacles whose inflated discs overlap (or whose detours
// would) are passed as one group on one side, and the detour is a lateral offset of the row with
// bounded curvature, driven at a speed that keeps the yaw rate and the lateral acceleration within
// their bounds. A group that cannot be passed (too wide, or the row ends in or just behind it) ends the
// path at the nearest safe point on the row before it, with a report.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/planning/potential_field.h"

namespace sowing_robot {
namespace core {

/// Parameters of the planned avoidance (YAML keys under `avoidance/`).
/// Defaults, ranges, units and meanings: avoidanceTable() (keys under field/avoidance/).
struct AvoidanceParams {
  AvoidanceParams();
  /// true: the target goes around the inflated obstacles (below); false: the thesis behaviour, only the
  /// potential field's repulsion from the raw obstacles (the footprint is ignored).
  bool plan_detours;
  /// Circumscribed radius of the footprint about base_link [m] (>= 0). Not a parameter: the node sets it
  /// from the URDF (footprintFromUrdf(...).circumscribedRadius(), 0.407 m for urdf/sowing_robot.urdf).
  double footprint_radius = 0.0;
  double safety_margin;      ///< body clearance the plan keeps from every obstacle [m] (>= 0)
  double max_curvature;      ///< curvature of the detours [1/m] (> 0)
  double max_yaw_rate;       ///< |omega| of the reference on a detour [rad/s] (> 0)
  double max_lateral_accel;  ///< |v omega| of the reference on a detour [m/s^2] (> 0)
  double max_offset;         ///< widest sideways detour [m] (> 0); a wider group is "no safe way"
  /// A stop before an obstacle (row end inside it, no safe way) keeps this much more clearance [m]
  /// (>= 0): at rest the robot still moves, e.g. +-0.11 m in x under the thesis disturbance (README).
  double stop_margin;
  /// Share of max_yaw_rate and max_lateral_accel the plan leaves to the controller [-] ([0, 0.9]): the
  /// reference uses (1 - tracking_reserve) of each, because the robot's own v omega swings above the
  /// reference's (the thesis disturbance alone moves v by about +-0.33 m/s).
  double tracking_reserve;
  std::string validate() const;
  /// Clearance of the planned axle-point path from an obstacle SURFACE [m]: footprint_radius +
  /// safety_margin, and at least `influence` (the potential field's zone), so the repulsion stays off
  /// along the plan.
  double pathClearance(double influence) const;
};

/// plan_detours, safety_margin, max_curvature, max_yaw_rate, max_lateral_accel, max_offset, stop_margin,
/// tracking_reserve.
const ParamTable<AvoidanceParams>& avoidanceTable();

/// What the reference can tell about its plan (for the node to log and publish).
struct AvoidanceStatus {
  enum class Code {
    kOk,            ///< every row is driven to its end
    kStoppedShort,  ///< a row end (the target) lies in or just behind an obstacle: stopped before it
    kNoSafeWay,     ///< a group of obstacles cannot be passed within max_offset: stopped before it
  };
  Code code = Code::kOk;
  std::string reason;         ///< one line for kStoppedShort / kNoSafeWay, else ""
  bool within_bounds = true;  ///< false: somewhere the curvature, yaw-rate or lateral-acceleration bound does not hold
  std::string bounds_note;    ///< why not (one line), else ""
  Eigen::Vector2d stop_point = Eigen::Vector2d::Zero();  ///< where the path ends when it stops short [m]
  std::size_t detours = 0;                               ///< planned detours
  static const char* name(Code c);
};

/// One detour along a row: lateral offset 0 -> offset over ramp_in, offset on the plateau, back to 0
/// over ramp_out. The ramps are cycloidal, y = H (tau - sin(2 pi tau) / (2 pi)), so the curvature is
/// continuous and peaks at 2 pi H / ramp^2 mid-ramp.
struct Detour {
  int row = 0;
  double begin = 0.0;                                   ///< along-row position where the up ramp starts [m]
  double ramp_in = 0.0, plateau = 0.0, ramp_out = 0.0;  ///< [m]
  double offset = 0.0;                                  ///< lateral offset on the plateau, + to the left of travel [m]
  double speed = 0.0;                                   ///< along-row speed over [begin, end()] [m/s]
  double peak_curvature = 0.0;                          ///< [1/m]
  std::vector<std::size_t> obstacles;                   ///< the group passed
  double end() const { return begin + ramp_in + plateau + ramp_out; }
  /// Offset y and dy/ds, d2y/ds2, d3y/ds3 at along-row position s (all 0 outside).
  void lateral(double s, double& y, double& y1, double& y2, double& y3) const;
};

/// The plan for one straight row from p0 along `heading` of `length`.
struct RowPlan {
  std::vector<Detour> detours;  ///< sorted, not overlapping
  bool cut = false;             ///< the path ends on this row at `stop`
  double stop = 0.0;            ///< along-row end of the path [m] (length when not cut)
};

/// Plans row `row`. `row_speed` caps the detour speed (so the speed along the path never exceeds it).
/// Updates `status` (code/reason on a cut, bounds, detour count).
RowPlan planRow(int row, const Eigen::Vector2d& p0, double heading, double length, double row_speed,
                const std::vector<Obstacle>& obstacles, const AvoidanceParams& params, double influence,
                AvoidanceStatus& status);

/// The obstacles the potential field's repulsion gets with a plan: each shrunk so that its influence
/// zone ends where the plan's clearance begins (radius r + pathClearance - influence), so the field is
/// off along the plan and pushes only a reference that strays inside an inflated obstacle.
std::vector<Obstacle> repulsionObstacles(const std::vector<Obstacle>& obstacles, const AvoidanceParams& params,
                                         double influence);

}  // namespace core
}  // namespace sowing_robot
