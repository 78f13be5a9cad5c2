#include "sowing_robot/core/planning/coverage_follower.h"

namespace sowing_robot {
namespace core {

PathParams coverageFollowerParams(const FieldParams& field, const CoverageParams& coverage) {
  FieldParams bounds = field;
  bounds.min_turn_radius = coverage.min_turn_radius;
  return fieldFollowerParams(bounds);
}

PathReference coverageReference(const CoveragePlan& plan, const Pose2D& start, const FieldParams& field,
                                const CoverageParams& coverage) {
  const CoveragePath route = coverageFrom(plan, start, coverage);
  return PathReference(coverageFollowerParams(field, coverage), start, route.points, route.tool_down);
}

}  // namespace core
}  // namespace sowing_robot
