// A coverage plan over a field with voids (field_boundary.h): headlands, swaths and one drivable route, as
// Fields2Cover and nav2's opennav_coverage plan them (docs/coverage.md).
//
//   * Headlands: headland_passes passes of the working width inside the outer boundary and around every void;
//     the inner field is the boundary shrunk by passes x width minus the voids grown by the same.
//   * Swaths: parallel lines one working width apart across the inner field at the swath heading (a number, or
//     "auto": the heading with the fewest swaths, searched over the boundary's edge directions and a sweep),
//     clipped to the inner field, so a swath cut by a void becomes two. Each swath carries its tool rows as
//     RowSegments (seeding.h), so the seed figures can judge them.
//   * Route: the swaths in boustrophedon (or skip) order within each part of the inner field that sweeps as one
//     (a void splitting the field makes two parts), the parts chained nearest first. Consecutive swaths are
//     joined by a HeadlandTurn (field.h) where the next swath starts at the same along-row position, by a
//     straight piece and a HeadlandTurn where the ends are staggered, and otherwise (between parts, onto the
//     headland) by a turn-straight-turn whose turns ramp their curvature as the field's turns do
//     (|kappa| <= 1/min_turn_radius, |dkappa/ds| <= max_curvature_rate). The headland passes are sown last, as
//     closed loops along the boundary's offset rings, their corners rounded to at least min_turn_radius.
//   * Headland rows: each straight side of a headland loop is a row of the plan (RowSegments after the swaths', in
//     the order driven), tool down along it; its corners (and the curves round circular voids) are driven tool up
//     and are no row (headlandSide).
//
// All polygon work (offsets, differences, clipping, areas, validity) is Boost.Geometry's; the interface keeps to
// Eigen points. Errors (a self-intersecting boundary or void, a void outside the field, a field narrower than
// one swath and its headlands, bad parameters) are thrown as std::invalid_argument with one line.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/planning/field_boundary.h"
#include "sowing_robot/core/planning/field_path_follower.h"
#include "sowing_robot/core/planning/seeding.h"

namespace sowing_robot {
namespace core {

/// The order of the swaths within a part: boustrophedon (neighbour after neighbour), skip (every second line
/// out, the ones between on the way back, so the turns are two widths wide), auto (skip where one width is
/// below 2 min_turn_radius, so the U-turns fit without a bulb).
enum class RoutePattern { kAuto, kBoustrophedon, kSkip };

/// Defaults, ranges, units and meanings: coverageTable() (keys coverage/...).
struct CoverageParams {
  CoverageParams();
  int rows_per_pass;          ///< tool rows sown in one pass, >= 1
  double row_spacing;         ///< distance between the tool's rows [m], > 0; working width = rows x spacing
  int headland_passes;        ///< passes round the boundary and every void, >= 0
  std::string heading;        ///< swath heading: "auto" or a number [rad]
  double min_turn_radius;     ///< every curve keeps |kappa| <= 1/min_turn_radius [m] (field/min_turn_radius)
  double max_curvature_rate;  ///< peak |dkappa/ds| of the turns [1/m^2] (field/max_curvature_rate)
  RoutePattern pattern;
  double sample_spacing;  ///< spacing of the route's points on its curves [m]
  double heading_step;    ///< step of the heading sweep of "auto" [rad]
  /// How far each swath is driven on past its end [m], >= 0: the tool point trails the axle by this much (the URDF's
  /// tool_link, as FieldParams::run_out), so the axle drives run_out past the row's end for the tool point to reach
  /// it, and the tool goes down where the tool point enters the row, run_out after the swath's start.
  double run_out;
  double workingWidth() const { return rows_per_pass * row_spacing; }
  /// The heading in force: "" and `out` set, or the error ("auto" leaves out untouched and returns "").
  std::string parseHeading(bool& is_auto, double& out) const;
  std::string validate() const;
};
/// coverage/{rows_per_pass, row_spacing, headland_passes, heading, min_turn_radius, max_curvature_rate,
/// pattern, sample_spacing, heading_step, run_out}.
const ParamTable<CoverageParams>& coverageTable();

/// One swath: its centre line from a to b in the direction it is driven, and its tool rows (same direction).
struct Swath {
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();
  std::vector<RowSegment> rows;
  int line = 0;  ///< index of its line across the field (0: the first line at the heading's right)
  int part = 0;  ///< the part of the inner field it belongs to
};

/// The plan: its parts for display as plain point lists, the swaths in route order and the route.
struct CoveragePlan {
  std::vector<Ring> field;           ///< the outer boundary, then the voids (circles as polygons)
  std::vector<Ring> inner_field;     ///< the inner field's rings (outer rings and holes)
  std::vector<Ring> headland_rings;  ///< the headland passes' centre lines, in the order they are driven
  std::vector<Swath> swaths;         ///< in route order
  /// The headland loops' straight sides as tool rows (headlandSide), in the order they are driven, after the swaths:
  /// rows_per_pass rows per side, centred on it, in the direction it is driven.
  std::vector<RowSegment> headland_rows;
  /// Swaths, turns and headland loops; tool down on each swath from run_out past its start to run_out past its end
  /// (the axle's stretch on which the tool point, run_out behind it, is over the row), and on the headland loops'
  /// straight sides (headlandSide), up on their corners.
  CoveragePath route;
  double heading = 0.0;                                 ///< the swath heading used [rad], in [0, pi)
  RoutePattern pattern = RoutePattern::kBoustrophedon;  ///< the pattern used (never kAuto)
  int parts = 0;                                        ///< parts of the inner field swept one after the other
  double working_width = 0.0;                           ///< [m]
  double path_length = 0.0;                             ///< the whole route [m]
  double turn_length = 0.0;                             ///< the route with the tool up [m]
  double peak_curvature = 0.0;       ///< largest |kappa| planned on the turns and headland loops [1/m]
  double peak_curvature_rate = 0.0;  ///< largest |dkappa/ds| planned on the turns [1/m^2]
  /// Joins for which no turn-straight-turn was found, driven as a straight line instead (0 expected).
  int straight_joins = 0;
  /// Every swath's tool rows, in route order, then the headland rows: the plan's rows (FieldPlan, SeedDrill).
  std::vector<RowSegment> rows() const;
  /// How many of rows() are the swaths' (the headland rows follow them).
  std::size_t swathRows() const;
};

/// True when a headland loop's edge from p to q (driven that way) is a straight side sown as a row: the stretch the
/// tool point sows on it, from p to run_out short of q (the tool point trails the axle by run_out, and the axle turns
/// into the next corner at q), is at least one working width long. The corners' chords (rounded to 1.1
/// min_turn_radius: 9.6 cm at 0.5 m) and those of the rings round circular voids are shorter, and are no row.
bool headlandSide(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const CoverageParams& params);

/// The rows of a headland side from p to q (headlandSide): rows_per_pass rows from p to run_out short of q, centred on
/// the side, each row_spacing apart.
std::vector<RowSegment> headlandSideRows(const Eigen::Vector2d& p, const Eigen::Vector2d& q,
                                         const CoverageParams& params);

/// "" when the boundary can be planned on, else one line: a ring with too few points or non-finite ones, a
/// self-intersecting boundary or void (Boost.Geometry's reason), a void (polygon or circle) outside the field.
std::string checkBoundary(const FieldBoundary& field);

/// The plan over `field`. Throws std::invalid_argument with one line (checkBoundary, params.validate(), or a
/// field narrower than one swath plus its headlands).
CoveragePlan planCoverage(const FieldBoundary& field, const CoverageParams& params);

/// The plan's route from a start pose [m, m, rad]: a tool-up approach (a turn-straight-turn with the route's
/// turn bounds) from the pose onto the first swath, heading along it, then the route. A pure function of its
/// arguments; throws std::invalid_argument on invalid params, a non-finite pose or a plan without a route.
CoveragePath coverageFrom(const CoveragePlan& plan, const Pose2D& start, const CoverageParams& params);

/// A tool-up join from pose `from` to pose `to` [m, m, rad] within the route's turn bounds, as the route joins its
/// parts: a U-turn (after a straight) between opposite headings offset sideways, else the shortest
/// turn-straight-turn (a straight line, as the route's straight joins, where none is found). Its points run from
/// from's position to to's (one point, no segment, when the poses coincide). A pure function of its arguments; throws
/// std::invalid_argument on invalid params or a non-finite pose. For sub-routes (a fleet's share, fleet_split.h).
CoveragePath coverageJoin(const Pose2D& from, const Pose2D& to, const CoverageParams& params);

}  // namespace core
}  // namespace sowing_robot
