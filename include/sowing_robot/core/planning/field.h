// A field of parallel rows driven in alternating directions and chained by headland U-turns, as a
// target for the potential field (so obstacles on the rows are avoided and every quantity the
// controllers need stays continuous).
//
// Geometry: row i runs from start_i to start_i + row_length u_i with u_i = +-(cos heading, sin heading)
// (even rows along the heading, odd rows back); start_{i+1} is start_i's end moved by row_spacing
// sideways. The headland turns are curvature-continuous: the curvature goes through cosine ramps
// (|dkappa/ds| <= max_curvature_rate) and holds, and its profile is symmetric, so a turn ends exactly
// row_spacing to the side at the same along-row position, heading reversed:
//   * wide enough (spacing large against min_turn_radius): 0 -> kappa -> 0, a "rounded semicircle";
//   * too narrow: a bulb (Omega) turn 0 -> -lambda kappa_max -> kappa_max -> -lambda kappa_max -> 0,
//     first swinging away from the next row, with lambda in (0, 1] and, if needed, arcs at -kappa_max.
// Speed: row_speed on the rows, turn_speed on the turns; every change is a half-cosine speed ramp
// (|v_dot| <= max_accel, v_dot continuous) done on the row, so the turn is entered at turn_speed.
// The last row ends at rest.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/planning/approach.h"
#include "sowing_robot/core/planning/detour.h"
#include "sowing_robot/core/planning/potential_field.h"

namespace sowing_robot {
namespace core {

/// What follows the field's rows and turns: the potential field (the thesis's reference, steering round the obstacles
/// also by repulsion) or the path follower of input:=path on the field as a path (field_path_follower.h).
enum class FieldFollower { kPotential, kPath };

/// Defaults, ranges, units and meanings: fieldTable() (keys field/... and potential/...).
struct FieldParams {
  FieldParams();
  int rows;                 ///< number of rows N, >= 1
  double row_length;        ///< [m], > 0
  double row_spacing;       ///< distance between neighbouring rows [m], > 0
  double start_x, start_y;  ///< start of the first row [m] (thesis: (0, 3))
  double heading;           ///< direction of the first row [rad]
  bool rows_to_left;        ///< the second row lies left of the first one's direction
  double row_speed;         ///< v_r [m/s], > 0
  double turn_speed;        ///< speed on the headland turns [m/s], in (0, row_speed]
  double min_turn_radius;   ///< the turns keep |kappa| <= 1/min_turn_radius [m], > 0
  double max_accel;         ///< peak |v_dot| of the speed ramps [m/s^2], > 0
  /// Peak |dkappa/ds| in the turns [1/m^2]; must be >= 1/(2 min_turn_radius^2) so a ramp to the
  /// largest curvature fits in a half turn.
  double max_curvature_rate;
  bool start_from_rest;  ///< false: the path starts at row_speed (as the thesis line)
  /// With a start_pose and avoidance.plan_detours: the path starts at the robot, on an approach that
  /// joins the first row within the detours' bounds (approach.h); false: it starts at the row start.
  bool approach;
  double approach_settle;  ///< the tool stays up this far past the approach's join [m], >= 0
  FieldFollower follower;  ///< field/follower: potential (default) or path
  /// The robot's start pose [m, m, rad]. Not a parameter: the caller sets it (the node from plant_sim's
  /// start/{x, y, theta}, as avoidance.footprint_radius from the URDF). Unset: no approach.
  std::optional<Pose2D> start_pose;
  /// How far the seed drill's tool point trails the axle [m] (>= 0). With avoidance.plan_detours every row is driven
  /// this much past its end (the last one to rest, the others into their headland turn), so the tool point reaches
  /// the row's end on its line and sows it (a turn started at the axle's row end swings the tool off the line, and
  /// the drill lifts, short of the end); the turn then ends this much before the next row's start, a straight
  /// lead-in. An approach joins the first row approach_settle + run_out before its start. Not a parameter: the
  /// caller sets it from the URDF's tool_link (0.45 m). 0, or without avoidance.plan_detours (the thesis path):
  /// the rows, turns and approach are the thesis's.
  double run_out = 0.0;
  PotentialFieldParams potential;  ///< alpha, beta, repulsion (see PotentialField)
  AvoidanceParams avoidance;       ///< planned detours around the inflated obstacles (detour.h)
  std::string validate() const;
};
/// field/{rows, row_length, row_spacing, start_x, start_y, heading, rows_to_left, row_speed, turn_speed,
/// min_turn_radius, max_accel, max_curvature_rate, start_from_rest, approach, approach_settle} and potential/...
/// (potentialFieldTable()).
const ParamTable<FieldParams>& fieldTable();

/// One headland U-turn in a local frame: starts at the origin heading along +x, turns left and ends at
/// (0, width) heading along -x. Built once; evaluation does not allocate.
class HeadlandTurn {
 public:
  HeadlandTurn() = default;
  /// Throws std::invalid_argument if no turn fits (validate FieldParams first).
  HeadlandTurn(double width, double max_curvature, double max_curvature_rate);

  double length() const { return length_; }                 ///< arc length [m]
  double peakCurvature() const { return peak_curvature_; }  ///< max |kappa| [1/m]
  bool isBulb() const { return bulb_; }                     ///< true for an Omega turn (swings away first)
  /// Position [m], heading [rad], curvature [1/m] and dkappa/ds [1/m^2] at arc length s (clamped).
  void evaluate(double s, Eigen::Vector2d& p, double& theta, double& kappa, double& dkappa) const;

 private:
  struct Segment {
    double s0 = 0.0, length = 0.0;  ///< start and length along the turn [m]
    double k0 = 0.0, k1 = 0.0;      ///< curvature at start and end (a cosine ramp if they differ) [1/m]
    double theta0 = 0.0;            ///< heading at the start [rad]
    double node_step = 0.0;         ///< spacing of the stored positions [m]
    std::size_t first_node = 0;     ///< index of its first stored position
    int nodes = 0;                  ///< stored positions inside it (its start included)
  };
  /// Curvature levels 0 -> -lambda k -> k -> -lambda k -> 0 holding -lambda k for `away` [m];
  /// false if the heading cannot add up to pi.
  bool build(double k, double lambda, double away, double rate);
  static void segmentState(const Segment& g, double tau, double& theta, double& kappa, double& dkappa);
  static Eigen::Vector2d integrate(const Segment& g, double a, double b);  ///< int_a^b (cos, sin) theta

  std::vector<Segment> segments_;
  std::vector<Eigen::Vector2d> nodes_;
  Eigen::Vector2d end_ = Eigen::Vector2d::Zero();
  double length_ = 0.0, peak_curvature_ = 0.0;
  bool bulb_ = false;
};

/// The whole field as a target trajectory (rows, turns and the speed profile); a pure function of t.
/// With obstacles and avoidance.plan_detours, the rows carry planned detours (detour.h) driven at their
/// detour speed, and the path ends early, at rest, before a group it cannot pass. With a plan, approach
/// and a start_pose off the row start, the path begins at that pose on an approach (tool up) that joins
/// the first row's line, approach_settle + run_out before its start where it fits (later where not); the
/// part of the row before the join is not driven. With a plan the rows run on by run_out past their ends
/// (FieldParams::run_out).
class FieldPath : public TargetTrajectory {
 public:
  /// Throws std::invalid_argument on invalid parameters or obstacles.
  explicit FieldPath(const FieldParams& params, const std::vector<Obstacle>& obstacles = {});
  TargetState at(double t) const override;
  std::unique_ptr<TargetTrajectory> clone() const override { return std::make_unique<FieldPath>(*this); }

  double duration() const { return duration_; }    ///< time at which the target stops [s]
  double length() const { return total_length_; }  ///< path length [m]
  const HeadlandTurn& turn() const { return turn_; }
  /// True when the path at time t is on a headland turn (tool up).
  bool onTurn(double t) const;
  /// Start point of row i [m].
  Eigen::Vector2d rowStart(int i) const;
  /// The plan: its status and its detours (empty without obstacles or with plan_detours false).
  const AvoidanceStatus& status() const { return status_; }
  const std::vector<Detour>& detours() const { return detours_; }
  /// True when the path starts on an approach; approach().why says why a needed one did not fit (the
  /// path then starts at the row start and status().within_bounds is false).
  bool hasApproach() const { return has_approach_; }
  const ApproachPlan& approach() const { return approach_; }

 private:
  struct Element {
    double s0 = 0.0, length = 0.0;
    std::size_t detour_first = 0, detour_count = 0;  ///< its detours in detours_ (rows only)
    bool turn = false;
    bool approach = false;   ///< the approach from the start pose (tool up)
    double along0 = 0.0;     ///< along-row position where a row's driven part starts (join, lead-in: < 0) [m]
    double tool_from = 0.0;  ///< along-row position from which the tool may go down (join + settle) [m]
    Eigen::Vector2d p0 = Eigen::Vector2d::Zero();
    double heading = 0.0;  ///< direction at the start [rad]
    double side = 1.0;     ///< +1 left turn, -1 right turn
  };
  /// From t0: s0 + v0 tau (+ half-cosine ramp to v1 over `duration` when v1 != v0).
  struct Phase {
    double t0 = 0.0, s0 = 0.0, duration = 0.0, v0 = 0.0, v1 = 0.0;
  };
  void addPhase(double distance, double v0, double v1);
  /// How far before the first row's start the approach joins its line at the earliest [m]: approach_settle +
  /// run_out with a plan (the tool is down before the tool point reaches the row), else 0.
  double approachLead() const;
  /// Plans approach_ from params_.start_pose to `row` (the first, planned); v_out: its end speed.
  void planApproach(const Element& row, double v_out, const std::vector<Obstacle>& obstacles);
  /// Speed phases of one row of `length` from v_in to v_out through its detours' speed windows.
  /// An approach of length `lead` (driven at lead_speed after its start ramp) comes first when lead > 0.
  void addRowPhases(double length, double v_in, double v_out, const Element& row, double lead = 0.0,
                    double lead_speed = 0.0);
  void arcLength(double t, double& s, double& sd, double& sdd, double& sddd) const;

  FieldParams params_;
  HeadlandTurn turn_;
  std::vector<Element> elements_;
  std::vector<Phase> phases_;
  std::vector<Detour> detours_;
  AvoidanceStatus status_;
  ApproachPlan approach_;
  bool has_approach_ = false;
  double duration_ = 0.0, total_length_ = 0.0;
};

/// What a field run needs of its reference, whichever follower drives the rows (FieldParams::follower):
/// FieldReference (potential) or FieldPathReference (path, field_path_follower.h).
class FieldSource : public ReferenceSource {
 public:
  /// True once the path has ended at time t: the reference then holds the last row's end (or a stop short).
  virtual bool finished(double t) const = 0;
  virtual double duration() const = 0;  ///< [s] when the path in force ends
  /// Replace the obstacles at run time and re-plan (throws std::invalid_argument, keeping the old ones).
  virtual void setObstacles(std::vector<Obstacle> obstacles) = 0;
  virtual const std::vector<Obstacle>& obstacles() const = 0;  ///< as given (not inflated)
  virtual const AvoidanceStatus& status() const = 0;           ///< the plan's status
  virtual const FieldPath& path() const = 0;                   ///< the rows, turns and detours planned
  virtual const FieldParams& params() const = 0;
};

/// Reference for a whole field: PotentialField tracking of a FieldPath.
class FieldReference : public FieldSource {
 public:
  /// Throws std::invalid_argument on invalid parameters or obstacles. With avoidance.plan_detours the
  /// path is planned around the obstacles (FieldPath) and the repulsion gets repulsionObstacles().
  explicit FieldReference(const FieldParams& params, std::vector<Obstacle> obstacles = {});

  std::unique_ptr<ReferenceSource> clone() const override;

  /// True once the path has ended (t >= duration()); the reference then stops at the last row's end.
  bool finished(double t) const override { return t >= duration_; }
  double duration() const override { return duration_; }  ///< [s]

  /// Replace the obstacles at run time (throws std::invalid_argument, keeping the old ones). With a plan,
  /// the path is re-planned as if the new list had been known from the start; the reference point and
  /// its velocity are kept, so where the new plan differs from the old one at the current time (the
  /// obstacle came too close ahead to plan for) the potential field pulls the reference onto it and
  /// status().within_bounds turns false.
  void setObstacles(std::vector<Obstacle> obstacles) override;
  /// The obstacles as given (not inflated).
  const std::vector<Obstacle>& obstacles() const override { return obstacles_; }
  /// The plan's status: the node logs it and publishes it (a stop, no safe way, bounds not held).
  const AvoidanceStatus& status() const override { return status_; }
  /// See PotentialField::setGains.
  void setGains(double alpha, double beta, double gain, double tangential_ratio) {
    field_.setGains(alpha, beta, gain, tangential_ratio);
  }
  const PotentialField& potentialField() const { return field_; }
  const FieldPath& path() const override { return static_cast<const FieldPath&>(field_.target()); }
  const FieldParams& params() const override { return params_; }

 protected:
  void restart() override { field_.reset(); }
  /// Reference at t; tool_down = true on rows, false on turns and once finished. Once the path has ended
  /// (finished(t): the last row's end, or a stop short of an obstacle) and the reference has come to rest
  /// (slower than potential/heading_hold_speed), it is a stop hold (Reference::stop).
  Reference evaluate(double t) override {
    Reference r = field_.next(t);
    r.stop = t >= duration_ && r.v <= field_.params().heading_hold_speed;
    return r;
  }

 private:
  FieldParams params_;
  std::vector<Obstacle> obstacles_;
  PotentialField field_;
  double duration_ = 0.0;
  AvoidanceStatus status_;
};

}  // namespace core
}  // namespace sowing_robot
