// How well a coverage plan (coverage_planner.h) covers its field, and the area a seed record sowed. Purely
// geometric (Boost.Geometry areas of the tool's strips), so it lives beside the planner.
//
// Covered: the union of the strips a tool of the working width sweeps along the swaths and the headland loops (flat
// at their ends; the tool's, not the axle's, which drives each swath on by its run-out). Overlap: the strips' summed
// areas minus their union, as a share of the union (0 when no ground is sown twice). Missed: the workable field (the
// boundary minus the voids) not covered, as a share of the workable field. Row area: the same of the plan's rows (the
// swaths' and the headland sides'), each a row spacing wide.
#pragma once

#include <vector>

#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/core/planning/field_boundary.h"
#include "sowing_robot/core/planning/seeding.h"

namespace sowing_robot {
namespace core {

struct CoverageFigures {
  double field_area = 0.0;     ///< inside the outer boundary [m^2]
  double workable_area = 0.0;  ///< the boundary minus the voids [m^2]
  double inner_area = 0.0;     ///< inside the headlands: the inner field [m^2]
  double covered_area = 0.0;   ///< the strips' union inside the workable field [m^2]
  /// The rows' strips (each a row spacing wide, flat ends) inside the workable field: what the plan sows when every
  /// row is sown end to end, without the headland loops' corners (no row) [m^2]. areaSown's counterpart.
  double row_area = 0.0;
  double covered_inner_share = 0.0;  ///< share of the inner field the swaths' strips cover
  double covered_share = 0.0;        ///< share of the workable field covered (swaths and headlands)
  double overlap_share = 0.0;        ///< (sum of the strips - their union) / union
  double missed_share = 0.0;         ///< (workable - covered) / workable
  double outside_share = 0.0;        ///< share of the union outside the workable field (sown into a void or off it)
  int swaths = 0;
  double path_length = 0.0;  ///< [m]
  double turn_length = 0.0;  ///< tool up [m]
};

/// The figures of `plan` over `field` (the field it was planned on).
CoverageFigures coverageFigures(const FieldBoundary& field, const CoveragePlan& plan);

/// The area a seed record sowed [m^2]: the union of the strips of `width` [m] along consecutive seeds (by time)
/// on the same row closer than 1.5 x `spacing` (the drill's seed spacing [m]); a run's strip ends at its first
/// and last seed, so a lone seed sows nothing. Throws std::invalid_argument on width or spacing <= 0.
double areaSown(const std::vector<Seed>& seeds, double width, double spacing);

}  // namespace core
}  // namespace sowing_robot
