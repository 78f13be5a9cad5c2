// A coverage plan driven: the path follower (path_plan.h) on the plan's route from the robot's start pose, with the
// field's speeds and the plan's turn bound. The nodes and the in-process runs build the reference here, so both
// drive the same one.
#pragma once

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/path_plan.h"

namespace sowing_robot {
namespace core {

/// fieldFollowerParams(field) with the plan's own turn bound (coverage/min_turn_radius) in place of the field's: the
/// speeds (row_speed, turn_speed, max_accel) are the field's, the curves the plan's.
PathParams coverageFollowerParams(const FieldParams& field, const CoverageParams& coverage);

/// The follower on coverageFrom(plan, start, coverage) (a tool-up approach from `start`, then the route), from `start`
/// at rest. Throws std::invalid_argument as coverageFrom and PathReference do.
PathReference coverageReference(const CoveragePlan& plan, const Pose2D& start, const FieldParams& field,
                                const CoverageParams& coverage);

}  // namespace core
}  // namespace sowing_robot
