// A run's seed record, kept beside the loop from the periods it hands its trace: the seed drill's own rule
// (SeedDrill::drop) on the tool point of the TRUE pose (where the seed really falls), with the tool point of the
// FED pose as where the robot believed it fell. The drill sows where the reference asks for the tool and the
// hitch does not hold it up -- what the node pipeline's seed_drill does with follow_hitch -- at the depth the
// drill runs at (the traction plant's tool depth, set by the depth control; without a tool in the plant the drill's
// nominal, the middle of the agronomic band).
// Used by the benchmark's rows (RowMeter), hence the tuner, and by the Python module: one record, one rule.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "sowing_robot/core/control/hitch_control.h"
#include "sowing_robot/core/planning/seeding.h"
#include "sowing_robot/core/simulation/closed_loop.h"
#include "sowing_robot/core/simulation/loop_types.h"

namespace sowing_robot {
namespace core {

class SeedRecorder {
 public:
  /// plan: the rows and obstacles sown against (a fresh drill: nothing travelled yet); tool: the seed-drop point
  /// in base_link [m].
  SeedRecorder(SeedDrill plan, const Eigen::Vector2d& tool)
      : drill_(std::move(plan)), tool_(tool), depth_(0.5 * (drill_.params().depth_min + drill_.params().depth_max)) {}

  /// A period of a truth-fed loop: the robot believed what was true (its yaw through the quaternion of
  /// nav_msgs/Odometry, as the loop feeds it).
  void add(const LoopSample& s) {
    const State& x = *s.state;
    drop(s.t, toolPoint(x[X], x[Y], x[THETA]), toolPoint(x[X], x[Y], yawThroughQuaternion(x[THETA])),
         s.reference->tool_down, false, depth_);
  }
  /// A period of a loop with a feedback source and layers: the believed point from the fed pose, the tool held up
  /// by the hitch control sows nothing.
  void add(const EstimatedSample& s) {
    const State& x = *s.loop->state;
    const bool raised = s.layers != nullptr && s.layers->hitch != nullptr && s.layers->hitch->raised();
    drop(s.loop->t, toolPoint(x[X], x[Y], x[THETA]), toolPoint(s.fed.x, s.fed.y, s.fed.theta),
         s.loop->reference->tool_down, raised, s.tool_depth > 0.0 ? s.tool_depth : depth_);
  }

  const std::vector<Seed>& seeds() const { return seeds_; }
  /// Where the tool point passed over the rows and in which drill state (consecutive periods merged): what the
  /// seed figures put the unsown stretches down to.
  const std::vector<RowPass>& passes() const { return passes_; }
  std::vector<Seed> takeSeeds() { return std::move(seeds_); }
  const SeedDrill& drill() const { return drill_; }

 private:
  Eigen::Vector2d toolPoint(double x, double y, double theta) const {
    const double sn = std::sin(theta), c = std::cos(theta);
    return {x + c * tool_.x() - sn * tool_.y(), y + sn * tool_.x() + c * tool_.y()};
  }
  void drop(double t, const Eigen::Vector2d& truth, const Eigen::Vector2d& believed, bool tool_down, bool held_up,
            double depth) {
    Seed seed;
    if (drill_.drop(t, truth, believed, tool_down, held_up, depth, seed)) seeds_.push_back(seed);
    pass(truth, tool_down, held_up);
  }
  /// The tool point's pass over its nearest row, between the row's ends, in the drill's state after this period.
  void pass(const Eigen::Vector2d& p, bool tool_down, bool held_up) {
    const int row = p.allFinite() ? drill_.nearestRow(p) : -1;
    if (row < 0) {
      passing_ = false;
      return;
    }
    const RowSegment& r = drill_.rows()[static_cast<std::size_t>(row)];
    const double length = (r.b - r.a).norm();
    const double along = length > 0.0 ? (p - r.a).dot(r.b - r.a) / length : 0.0;
    if (!(along > 0.0 && along < length)) {
      passing_ = false;
      return;
    }
    const DrillState state = held_up            ? DrillState::held_up
                             : drill_.lowered() ? DrillState::down
                             : tool_down        ? DrillState::not_engaged
                                                : DrillState::not_asked;
    const bool same_row = passing_ && passes_.back().row == row;
    if (same_row && passes_.back().state == state) {
      passes_.back().from = std::min(passes_.back().from, along);
      passes_.back().to = std::max(passes_.back().to, along);
    } else {  // from the last period's point on, so that consecutive passes leave no gap between them
      const double from = same_row ? std::min(last_along_, along) : along;
      const double to = same_row ? std::max(last_along_, along) : along;
      passes_.push_back({row, state, from, to});
    }
    passing_ = true;
    last_along_ = along;
  }

  SeedDrill drill_;
  Eigen::Vector2d tool_;
  double depth_;
  std::vector<Seed> seeds_;
  std::vector<RowPass> passes_;
  bool passing_ = false;  // the last period's tool point was over a row (passes_.back())
  double last_along_ = 0.0;
};

}  // namespace core
}  // namespace sowing_robot
