// Following a given path (a nav_msgs/Path, a file of points): the polyline made drivable and timed.
//
// Geometry: the points are simplified (Douglas-Peucker, simplify_tolerance) and every corner gets a fillet
// whose curvature is a cosine bump, kappa(s) = (phi/L)(1 - cos(2 pi s/L)) over its length L, so curvature,
// heading and position are continuous and |dkappa/ds| is bounded: the outer loop gets a continuous omega_r and
// an analytic omega_dot. Each fillet is the shortest one within max_curvature (its peak is 2 phi/L), which cuts
// the corner least; where it does not fit between its neighbours (in half of each adjacent segment) the robot
// stops at the corner and turns in place (a pivot), as a differential drive can. A densely sampled curve becomes a
// chain of touching fillets whose curvature ripples between 0 and twice the curve's own: its speed limit follows the
// peak. Timing: every fillet is driven at one speed, min(v_max, sqrt(lateral_accel / peak curvature)); the speed
// changes on the straights by half-cosine ramps (|v_dot| <= a_max, v_dot continuous), planned with a forward and
// a backward pass; pivots and the end are at rest. A pivot turns by a cosine-bump yaw rate (peak <= turn_rate,
// peak yaw acceleration <= turn_accel).
// The plan starts from a given pose and speed (the robot's start, or the reference in force when a new path
// replaces the old one): a straight lead along the current heading, twice as long as the stop from the current
// speed, then the point of the path closest to the lead's end, so the reference stays continuous in pose and
// speed and the part of the path behind is skipped. After the end the reference holds the last point (a stop).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/common/types.h"

namespace sowing_robot {
namespace core {

/// Defaults, ranges, units and meanings: pathTable() (keys path/...).
struct PathParams {
  PathParams();
  double v_max;               ///< [m/s]
  double a_max;               ///< peak |v_dot| of the speed ramps [m/s^2]
  double lateral_accel;       ///< v^2 |kappa| <= this on the fillets [m/s^2]
  double max_curvature;       ///< peak curvature of a fillet [1/m]; a corner that needs more is a pivot
  double turn_rate;           ///< peak yaw rate of a pivot [rad/s]
  double turn_accel;          ///< peak yaw acceleration of a pivot [rad/s^2]
  double simplify_tolerance;  ///< Douglas-Peucker tolerance on the given points [m]; 0: every point kept
  double goal_tolerance;      ///< the goal counts as reached within this distance of the last point [m]
  bool tool_down;             ///< the reference's tool_down off the pivots (seeds along the path)
  std::string validate() const;
};
/// path/{v_max, a_max, lateral_accel, max_curvature, turn_rate, turn_accel, simplify_tolerance, goal_tolerance,
/// tool_down}.
const ParamTable<PathParams>& pathTable();

/// Douglas-Peucker simplification of an open polyline (first and last point kept); tolerance 0 keeps every
/// point but drops repeats closer than 1 mm.
std::vector<Eigen::Vector2d> simplifyPolyline(const std::vector<Eigen::Vector2d>& points, double tolerance);

/// Where a plan starts: a pose and the speed along its heading there [m/s] (>= 0).
struct PathStart {
  Pose2D pose;
  double v = 0.0;
};

/// A path made drivable and timed (see the file comment); at() is a pure function of the plan's own time.
class PathPlan {
 public:
  PathPlan() = default;  ///< no path: duration 0, at() holds the origin
  /// Throws std::invalid_argument for invalid params, a non-finite point or start, no point at all, or tool flags
  /// that are neither empty nor one per segment. tool[k]: the tool is down from points[k] to points[k + 1] (a
  /// rounded corner keeps it down only between two such segments; the lead from the start keeps it up); empty:
  /// params.tool_down along the whole path, the lead included.
  PathPlan(const std::vector<Eigen::Vector2d>& points, const PathStart& start, const PathParams& params,
           std::vector<bool> tool = {});

  /// The reference tau seconds after the plan's start (tau < 0 counts as 0); past duration(): the last
  /// point, at rest, with stop set.
  Reference at(double tau) const;
  double duration() const { return duration_; }  ///< [s] until the end point is reached at rest
  double length() const { return length_; }      ///< [m] of the drivable path
  Eigen::Vector2d goal() const;                  ///< the last point [m]
  /// Arc length the reference has covered tau seconds after the start [m].
  double arcLengthAt(double tau) const;
  /// The first time the reference reaches arc length s [s].
  double timeAt(double s) const;

  /// The point of the path closest to p among arc lengths [s_lo, s_hi]: its arc length, and the signed
  /// distance (positive when p lies left of the direction of travel) [m].
  struct Projection {
    double s = 0.0, cross_track = 0.0;
  };
  Projection project(const Eigen::Vector2d& p, double s_lo, double s_hi) const;

  int pivots() const { return pivots_; }            ///< corners turned in place
  int fillets() const { return fillets_; }          ///< corners rounded
  double maxCornerCut() const { return max_cut_; }  ///< largest distance of a fillet from its corner [m]
  const std::vector<Eigen::Vector2d>& vertices() const { return vertices_; }  ///< after joining and simplifying

 private:
  /// A piece of the drivable path: a straight, or a fillet of turning angle phi (signed, left +).
  struct Element {
    double s0 = 0.0, length = 0.0;
    Eigen::Vector2d p0 = Eigen::Vector2d::Zero();
    double theta0 = 0.0;
    double phi = 0.0;                    ///< fillets: turning angle [rad]; 0 for a straight
    double v_limit = 0.0;                ///< [m/s]
    std::vector<Eigen::Vector2d> nodes;  ///< fillets: positions every length/kFilletNodes
    bool tool_down = false;              ///< the reference's tool_down along it
  };
  /// A piece of the timeline: moving along [s0, s0 + ...] from v0 to v1, or a pivot at arc length s0.
  struct Phase {
    double t0 = 0.0, duration = 0.0, s0 = 0.0, distance = 0.0, v0 = 0.0, v1 = 0.0;
    bool pivot = false;
    double theta0 = 0.0, dtheta = 0.0;  ///< pivots: heading before and the turn [rad]
  };
  static constexpr int kFilletNodes = 32;

  void addStraight(const Eigen::Vector2d& from, double length, double heading, bool tool_down);
  /// The fillet of corner `vertex`, starting `tangent` before it on the incoming heading theta0.
  void addFillet(const Eigen::Vector2d& vertex, double tangent, double theta0, double phi, double length,
                 bool tool_down);
  /// The speed at every element boundary (forward and backward pass) and the phases; pivot_after[j]: the turn
  /// in place after element j (0: none).
  void planSpeeds(double v_start, const std::vector<double>& pivot_after);
  void addMove(double distance, double v0, double v1);
  void addPivot(double theta0, double dtheta);
  /// Position, heading, curvature and dkappa/ds at arc length s.
  void geometry(double s, Eigen::Vector2d& p, double& theta, double& kappa, double& dkappa) const;
  const Element& elementAt(double s) const;
  /// The phase in force tau seconds after the start (phases_ not empty).
  const Phase& phaseAt(double tau) const;

  PathParams params_;
  std::vector<Eigen::Vector2d> vertices_;
  std::vector<Element> elements_;
  std::vector<Phase> phases_;
  double duration_ = 0.0, length_ = 0.0, max_cut_ = 0.0, end_theta_ = 0.0;
  int pivots_ = 0, fillets_ = 0;
};

/// The reference of a path follower: holds the start pose (a stop) until a path is given; a new path replaces
/// the one in force from the reference last returned (its pose and speed), so the reference stays continuous.
class PathReference : public ReferenceSource {
 public:
  /// Follows `points` from `start` at rest (none: holds `start` until setPath()), with the tool flags of PathPlan.
  /// Throws std::invalid_argument for invalid params, points or flags.
  PathReference(const PathParams& params, const Pose2D& start, std::vector<Eigen::Vector2d> points = {},
                std::vector<bool> tool = {});
  std::unique_ptr<ReferenceSource> clone() const override;

  /// Follow `points` (tool flags as PathPlan's) from the reference last returned (from the start pose at rest before
  /// any). Throws std::invalid_argument (the path in force is kept) for a non-finite point, no point at all or
  /// flags that do not fit.
  void setPath(const std::vector<Eigen::Vector2d>& points, std::vector<bool> tool = {});
  bool hasPath() const { return has_plan_; }
  const PathPlan& plan() const { return plan_; }
  double planStart() const { return plan_t0_; }  ///< time at which the plan in force began [s]
  const PathParams& params() const { return params_; }

 protected:
  void restart() override;
  Reference evaluate(double t) override;

 private:
  PathParams params_;
  Pose2D start_;
  std::vector<Eigen::Vector2d> initial_points_;  ///< the path given at construction (reset() goes back to it)
  std::vector<bool> initial_tool_;               ///< and its tool flags
  PathPlan plan_;
  bool has_plan_ = false;
  double plan_t0_ = 0.0;
};

}  // namespace core
}  // namespace sowing_robot
