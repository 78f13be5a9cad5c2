// The seed drill: drops a seed every `spacing` metres the tool point travels while the tool is down,
// and scores the sown line against the intended rows (cross-track error), with detours around
// obstacles reported apart from the straight rows.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/potential_field.h"

namespace sowing_robot {
namespace core {

/// An intended sowing row: the straight segment from a to b [m].
struct RowSegment {
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();
};

/// The rows of a field (row i from rowStart(i), alternating direction, length row_length).
std::vector<RowSegment> rowsOf(const FieldParams& field);

/// Defaults, ranges, units and meanings: seedingTable().
struct SeedingParams {
  SeedingParams();
  double spacing;        ///< distance between seeds along the tool's path [m] (> 0)
  double tolerance;      ///< cross-track error counted as "off the line" beyond this [m] (> 0)
  double detour_margin;  ///< seeds closer than radius + influence + margin to an obstacle are detour seeds [m]
  /// The tool is lowered only once the tool point is this close to a row, between its ends, and the
  /// reference says tool down, as an operator would: the approach from a start off the row and the
  /// end of a headland turn sow nothing [m] (> 0).
  double engage_distance;
  std::string validate() const;
};
/// spacing, tolerance, detour_margin, engage_distance (seed_drill's keys).
const ParamTable<SeedingParams>& seedingTable();

/// Cross-track figures of a set of seeds [m].
struct SeedStats {
  std::size_t count = 0;
  double max = 0.0, rms = 0.0;
  double fraction_over = 0.0;  ///< share of seeds with |error| > tolerance
};

class SeedDrill {
 public:
  /// influence: the potential field's influence distance, so the detour zone follows the avoidance.
  SeedDrill(const SeedingParams& params, std::vector<RowSegment> rows, std::vector<Obstacle> obstacles,
            double influence);

  /// Advance the tool point to p; tool_down is the reference's request. Returns true (and the seed
  /// position) when a seed falls here. A non-finite p is refused (false, state untouched, counted by
  /// rejected()), so it can neither drop a seed nor spoil the distance travelled.
  bool update(const Eigen::Vector2d& p, bool tool_down, Eigen::Vector2d& seed);
  /// A new plan (the obstacles changed at run time): seeds from now on are scored against it; the
  /// seeds already scored, the distance travelled and the tool's state are kept.
  void setPlan(std::vector<RowSegment> rows, std::vector<Obstacle> obstacles, double influence);

  /// Distance from p to the nearest row segment [m].
  double crossTrack(const Eigen::Vector2d& p) const;
  /// True when p is within engage_distance of a row and between its ends (not beyond them, as in a
  /// headland turn): where the tool may be lowered.
  bool onRowSegment(const Eigen::Vector2d& p) const;
  /// True when p lies in an obstacle's detour zone.
  bool inDetour(const Eigen::Vector2d& p) const;

  const SeedStats& onRows() const { return rows_stats_; }     ///< seeds away from obstacles
  const SeedStats& detours() const { return detour_stats_; }  ///< seeds in detour zones
  std::string report() const;
  std::size_t rejected() const { return rejected_; }

 private:
  void score(SeedStats& s, double& sum_sq, std::size_t& over, double e);

  SeedingParams params_;
  std::vector<RowSegment> rows_;
  std::vector<Obstacle> obstacles_;
  double influence_;
  std::size_t rejected_ = 0;
  bool has_last_ = false;
  bool lowered_ = false;  // tool physically down
  Eigen::Vector2d last_ = Eigen::Vector2d::Zero();
  double travelled_ = 0.0;  // since the last seed, tool down only
  SeedStats rows_stats_, detour_stats_;
  double rows_sq_ = 0.0, detour_sq_ = 0.0;
  std::size_t rows_over_ = 0, detour_over_ = 0;
};

}  // namespace core
}  // namespace sowing_robot
