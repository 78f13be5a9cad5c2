// What a run's seeds are worth, from its seed record (core::Seed, planning/seeding.h) and the plan they were
// sown against (the SeedDrill's rows, obstacles and parameters): a seed-sowing robot is judged by the seeds it
// places, not by how closely its axle followed a moving target.
//
//  - Sown share, on the row's geometry: the seeds of a row projected on it; a stretch between two consecutive
//    seeds at most sown_gap x spacing apart is sown, and each seed sows half a spacing either side of it (so a
//    row sown end to end at the spacing is 100 % less the half spacing before its first seed and after its last).
//    The obstacle stretches, where an obstacle blocks the row (SeedDrill::blockedRadius: its radius + the plan's
//    clearance), are reported apart: the row cannot be sown on its line there. The rest of a detour, where the
//    robot leaves and rejoins the row, is row to sow (its seeds lie off the line, and are counted).
//  - ISO 7256-1 (single-seed drills; Kachman & Smith 1995 for the indices' definitions) on the spacings between
//    consecutive seeds along each row outside the obstacle stretches, x_ref = the drill's spacing: multiples index
//    D = share of spacings <= 0.5 x_ref, miss index M = share > 1.5 x_ref, quality of feed A = 100 - D - M, and
//    precision C = the standard deviation of the accepted spacings (0.5, 1.5] x_ref over x_ref. A long unsown
//    stretch is a single miss among hundreds of spacings: the sown share, not A, shows it.
//  - The seeds' lateral offset from their row's line (outside detour zones), the share placed outside the
//    agronomic depth band, and the seed-map error |believed - true position| (what a farmer's seed map is worth).
#pragma once

#include <cstddef>
#include <vector>

#include "sowing_robot/core/planning/seeding.h"

namespace sowing_robot {
namespace core {

/// One row's sowing [m].
struct RowSowing {
  double length = 0.0;         ///< the row's length outside obstacle stretches
  double sown = 0.0;           ///< of which sown
  double detour_length = 0.0;  ///< the row's length inside obstacle stretches
  double detour_sown = 0.0;    ///< of which sown (by seeds projected onto it)
  /// Of the unsown length outside obstacle stretches: before the first seed's stretch (the whole row without a
  /// seed) and after the last seed's; the rest lies between seeds (mid-row).
  double unsown_start = 0.0, unsown_end = 0.0;
  double share() const { return length > 0.0 ? sown / length : 1.0; }
};

/// A run's seed figures; NaN where there is nothing to measure (no rows, no seeds, no spacings).
struct SeedFigures {
  std::size_t seeds = 0;
  std::vector<RowSowing> rows;  ///< per row of the plan, in its order
  double sown_share;            ///< sown length / length over every row, outside obstacle stretches
  double worst_row_share;       ///< the least-sown row's share
  double detour_sown_share;     ///< sown share of the obstacle stretches (NaN without any)
  double multiples, misses, quality_of_feed, precision;  ///< ISO 7256-1 D, M, A, C [%]
  double lateral_rms, lateral_p95, lateral_max;          ///< seeds outside detour zones, from their row's line [m]
  double depth_outside;                                  ///< share of the seeds outside [depth_min, depth_max]
  double map_error_rms, map_error_p95;                   ///< |believed - true position| [m]
  /// Where the rows' unsown length lies, summed over the rows, outside obstacle stretches [m]: before each row's
  /// first seed (row start), after its last (row end), between seeds (mid-row). NaN without rows.
  double unsown_start, unsown_end, unsown_mid;
  /// Why, where the tool point's passes are known (the seed recorder's RowPass; NaN without): unsown length the tool
  /// point passed over with the drill held up by the hitch; else asked for but not yet engaged (engage_distance);
  /// else not asked for by the plan [m]. The rest was passed with the drill down (the spacing before a lowered
  /// drill's first seed) or never passed over.
  double unsown_held_up, unsown_not_engaged, unsown_not_asked;
  SeedFigures();
};

/// Consecutive seeds at most this many spacings apart sow the stretch between them.
constexpr double kSownGap = 1.5;

/// The figures of `seeds` sown against `plan` (its rows, obstacles, spacing and depth band); `passes` (the seed
/// recorder's, optional) puts the unsown length down to the drill's state.
SeedFigures seedFigures(const std::vector<Seed>& seeds, const SeedDrill& plan,
                        const std::vector<RowPass>* passes = nullptr);

}  // namespace core
}  // namespace sowing_robot
