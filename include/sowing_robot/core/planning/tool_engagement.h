// When the seed drill's tool is down, decided by the plant itself (the tool's draft loads it), from
// the plan's rows and the true tool point only, so a lockstep run stays deterministic (no asynchronous
// topic enters a step).
//
// Rule: the tool is lowered where the seed drill lowers it -- SeedDrill::onRowSegment (core/planning/seeding.h:
// the tool point within engage_distance of a row, between its ends) -- and raised where the reference's
// tool_down goes false on a field: on the headland turns, i.e. once the tool point is beyond the ends of
// every row (an open-ended row, the line, has no far end). Two documented differences to the seed
// drill, which also needs the reference's tool_down: on an approach the draft starts when the tool
// point first reaches the row, not after approach_settle (with a planned field's run_out the settle ends
// before the row's start, FieldPath); and after the field's end the tool stays down (the robot is at rest
// there, and the draft with it).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "sowing_robot/core/planning/seeding.h"

namespace sowing_robot {
namespace core {

class ToolEngagement {
 public:
  ToolEngagement() : ToolEngagement(SeedingParams(), {}) {}
  /// open_ended: the rows go on past their ends (FieldPlan::open_ended, the thesis line).
  ToolEngagement(const SeedingParams& params, std::vector<RowSegment> rows, bool open_ended = false);
  /// A new plan; the tool's state is kept (as SeedDrill::setPlan).
  void setPlan(std::vector<RowSegment> rows, bool open_ended);
  /// The tool point at p (non-finite: ignored); returns down().
  bool update(const Eigen::Vector2d& p);
  bool down() const { return down_; }
  /// True when p lies between the ends of some row (its projection strictly inside; past the end too
  /// for an open-ended plan): SeedDrill::withinRowSpan.
  bool withinRows(const Eigen::Vector2d& p) const;

 private:
  SeedDrill geometry_;  // the plan's rows and the seed drill's own rules (onRowSegment, withinRowSpan)
  bool open_ended_ = false;
  bool down_ = false;
};

}  // namespace core
}  // namespace sowing_robot
