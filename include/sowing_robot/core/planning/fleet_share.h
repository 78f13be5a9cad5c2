// One robot of a fleet sharing a field, as the nodes drive it (fleet.launch field_file:=): which share of the split
// plan (fleet_split.h) it drives from which start pose, and the reference it follows with the run-time yield.
//   * Starts (fleetStarts): the robots side by side, start_spacing apart along the field's bounding box's south
//     side, start_back south of it and from start_x east of its south-west corner, facing north (the poses
//     fleet_bench plans with). Every robot plans the same field with the same starts, so every robot's split is the
//     same (the planner and the split are pure functions) and robot `index` drives the share whose robot is index.
//   * planFleetShare: the split (splitCoverage) and, with keep_apart, the planned start waits (keepApart).
//   * FleetShareReference: the share's path through the path follower, standing (Reference::stop, the hold path of
//     docs/stops.md) at its start during the planned wait, and slowed to a stop and back while the fleet's verdict
//     says hold: the source's time runs at a rate that ramps between 1 and 0 in ramp_time seconds (the reference's
//     speed and acceleration scaled as the time is), and at rate 0 the reference stands where it is with stop set.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/planning/fleet_split.h"
#include "sowing_robot/core/planning/path_plan.h"

namespace sowing_robot {
namespace core {

struct FleetShareParams {
  int robots = 0;  ///< robots sharing the field; 0: not a fleet (one robot on the whole route)
  int index = 0;   ///< this robot (its start pose and its share)
  double start_x = 5.0, start_spacing = 5.0, start_back = 5.0;  ///< [m] the start poses (fleetStarts)
  bool keep_apart = true;                                       ///< plan the start waits (keepApart)
  FleetParams plan;                                             ///< keepApart's settings
  bool yield = false;            ///< wait for the fleet's verdicts (fleet_monitor) and hold when told
  double decision_period = 0.1;  ///< [s] of simulated time between verdicts
  double ramp_time = 2.0;        ///< [s] the reference's time rate from 1 to 0 (a hold) or back
  std::string validate() const;
};
/// fleet/{robots, index, start_x, start_spacing, start_back, keep_apart, safety_distance, stretch_length,
/// time_step, wait_step, max_wait, yield, decision_period, ramp_time}.
const ParamTable<FleetShareParams>& fleetShareTable();

/// The start poses of `params.robots` robots beside the field `outer` (its outer ring).
std::vector<Pose2D> fleetStarts(const Ring& outer, const FleetShareParams& params);

/// The pose the plan's route begins at: its first point, heading along its first segment.
Pose2D routeStart(const CoveragePlan& plan);

/// The fleet's plan: splitCoverage from fleetStarts, then keepApart with keep_apart. `share` is the index into
/// plan.shares of robot params.index's share. Throws std::invalid_argument as splitCoverage and keepApart do.
struct FleetShare {
  FleetPlan fleet;
  int share = 0;
  const RobotShare& own() const { return fleet.shares[static_cast<std::size_t>(share)]; }
};
FleetShare planFleetShare(const CoveragePlan& plan, const FleetShareParams& params, const CoverageParams& coverage,
                          const PathParams& follower);

/// A fleet robot's reference: `source` (its share's path from its start, at rest at t = 0 of the source) after
/// `wait` seconds standing at the start, held and released by setHold().
class FleetShareReference : public ReferenceSource {
 public:
  /// Throws std::invalid_argument for wait < 0 or ramp_time <= 0 (not finite).
  FleetShareReference(std::unique_ptr<PathReference> source, double wait, double ramp_time);
  /// The verdict for the references from the next one on: hold (slow to a stop and stand) or drive.
  void setHold(bool hold) { hold_ = hold; }
  bool hold() const { return hold_; }
  /// The planned wait is over at the last reference.
  bool started() const { return started_; }
  /// The share of the path's time driven [0, 1] at the last reference (1: at its end).
  double progress() const;
  /// Standing still for a hold at the last reference (rate 0, not the planned wait).
  bool standing() const { return started_ && rate_ <= 0.0; }
  double rate() const { return rate_; }
  const PathReference& path() const { return *source_; }
  std::unique_ptr<ReferenceSource> clone() const override;

 protected:
  void restart() override;
  Reference evaluate(double t) override;

 private:
  std::unique_ptr<PathReference> source_;
  double wait_, ramp_;
  bool hold_ = false, started_ = false, first_ = true;
  double rate_ = 1.0, tau_ = 0.0, last_t_ = 0.0;
  double lost_ = 0.0;  ///< [s] of source time the holds took
};

}  // namespace core
}  // namespace sowing_robot
