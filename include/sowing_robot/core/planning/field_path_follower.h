// The field's rows and headland turns as one producer of paths for the path follower (field/follower: path), so a
// field and a user's nav_msgs/Path share one follower (path_plan.h): the same rounding, timing, progress and stop.
//
// The producer samples the field's planned path (FieldPath: the approach, the rows with their planned detours round
// the obstacles, the headland turns, an early stop before a group it cannot pass) into points with a tool flag per
// segment: down where the field lowers the tool (rows, detours, past the approach's settle), up on the turns and the
// approach. The follower then rounds the corners of those points again: a sampled curve becomes a chain of short
// fillets that peak at the follower's max_curvature, so its speed limit there is sqrt(lateral_accel / max_curvature)
// (docs/interfaces.md). The speeds come from the field's own keys (fieldFollowerParams): nothing of the field is
// configured twice. What the potential field adds and the path follower does not have: repulsion from obstacles
// that the plan did not know of in time (a run-time obstacle is re-planned and the new path replaces the old one
// from the robot's progress, as any new path does).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Dense>

#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/path_plan.h"

namespace sowing_robot {
namespace core {

/// A path with the tool's state on each segment: tool_down[k] holds from points[k] to points[k + 1].
struct CoveragePath {
  std::vector<Eigen::Vector2d> points;
  std::vector<bool> tool_down;
};

/// The field's planned path sampled every `spacing` metres [m] (> 0) and where the tool goes up or down; the points
/// inside straight stretches are left out (a row is one segment).
CoveragePath coveragePath(const FieldPath& path, double spacing);

/// The follower's parameters for a field: v_max = field/row_speed, a_max = field/max_accel, lateral_accel =
/// turn_speed^2 / min_turn_radius (the field's own bound on its turns), max_curvature = 2.5 / min_turn_radius (a
/// sampled turn's fillets need twice its curvature; 2.5 leaves room so none becomes a turn in place), every point
/// kept, the goal within 5 cm; the tool flags come from the field.
PathParams fieldFollowerParams(const FieldParams& field);

/// The field followed as a path: coveragePath() of its FieldPath through a PathReference.
class FieldPathReference : public FieldSource {
 public:
  /// Sample spacing of the field's path [m]: on the thesis field 5 cm gave the robot a peak yaw rate of 2.2 rad/s
  /// (the fillets' ripple, 6 Hz at 0.32 m/s), 15 cm 1.8, 30 cm 1.8 with the seeds' max off the row 3.3, 2.5, 2.4 mm;
  /// 50 cm turned in place on the 3-row field's turns (uneven segments at the row ends).
  static constexpr double kSpacing = 0.3;
  /// Throws std::invalid_argument on invalid parameters or obstacles (FieldPath) or a path the follower refuses.
  explicit FieldPathReference(const FieldParams& params, std::vector<Obstacle> obstacles = {});
  std::unique_ptr<ReferenceSource> clone() const override;

  /// True once the follower's plan in force has ended (the reference holds its last point, a stop).
  bool finished(double t) const override;
  double duration() const override;  ///< [s] the plan in force ends, from t = 0
  /// Re-plans the field round the new obstacles and replaces the path from the reference's progress.
  void setObstacles(std::vector<Obstacle> obstacles) override;
  const std::vector<Obstacle>& obstacles() const override { return obstacles_; }
  const AvoidanceStatus& status() const override { return path_->status(); }
  const FieldPath& path() const override { return *path_; }
  const FieldParams& params() const override { return params_; }
  /// The follower, for the node's progress reports (and a nav_msgs/Path that replaces the field's).
  PathReference& follower() { return follower_; }
  const CoveragePath& coverage() const { return coverage_; }

 protected:
  /// The follower on the field's path as planned now, from the start (as FieldReference: the obstacles in force
  /// as if known from the start).
  void restart() override;
  Reference evaluate(double t) override { return follower_.next(t); }

 private:
  /// The follower from the start of coverage_ (the constructor's and restart()'s).
  PathReference followerFromStart() const;

  FieldParams params_;
  std::vector<Obstacle> obstacles_;
  std::shared_ptr<const FieldPath> path_;  ///< shared by clones: immutable once built
  CoveragePath coverage_;
  PathReference follower_;
};

/// The field's reference for params.follower: a FieldReference or a FieldPathReference. Throws as they do.
std::unique_ptr<FieldSource> makeFieldSource(const FieldParams& params, std::vector<Obstacle> obstacles = {});

}  // namespace core
}  // namespace sowing_robot
