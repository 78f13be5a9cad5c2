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
  /// The agronomic depth band the seed is to be placed in [m] (0 < depth_min < depth_max): seeds outside it
  /// count against the run (seedFigures), and a depth control keeps the drill inside it.
  double depth_min, depth_max;
  std::string validate() const;
};
/// spacing, tolerance, detour_margin, engage_distance, depth_min, depth_max (seed_drill's keys).
const ParamTable<SeedingParams>& seedingTable();

/// One seed as it fell: the record of a run (runs.csv's seed figures, the node pipeline's `seeds` topic, the
/// CSV and GeoJSON seed maps are made from these).
struct Seed {
  double t = 0.0;                                      ///< when it fell [s]
  Eigen::Vector2d truth = Eigen::Vector2d::Zero();     ///< where it fell, odom frame [m]
  Eigen::Vector2d believed = Eigen::Vector2d::Zero();  ///< where the robot believed its tool was (fed pose) [m]
  int row = -1;                                        ///< the plan's row it lies nearest (-1: no rows)
  double depth = 0.0;                                  ///< depth it was placed at [m]
  bool detour = false;                                 ///< in an obstacle's detour zone (SeedDrill::inDetour)
};

/// The drill's state where the tool point passed over a row: what a row's unsown stretches are put down to
/// (seedFigures). held_up: the hitch held the drill up; not_engaged: the plan asked for it but the drill was not yet
/// lowered (the tool point not within engage_distance of the row's line since it was last lifted); not_asked: the
/// plan did not ask for it (the approach, a headland turn).
enum class DrillState { down, held_up, not_engaged, not_asked };

/// A stretch of a row the tool point passed over in one drill state, along the row from its start [m].
struct RowPass {
  int row = -1;
  DrillState state = DrillState::down;
  double from = 0.0, to = 0.0;
};

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
  ///
  /// The drill is lowered where the plan asks for the tool (tool_down) and the tool point is on a row (onRowSegment);
  /// it is lifted when held_up (the hitch holds it up: at once), or when the plan no longer asks for it and the
  /// tool point has left the rows' span (withinRowSpan) or the row's line (beyond tolerance): the plan's request
  /// turns with the axle's target into the headland at a row's end, while the tool point trails the axle by the
  /// drill's offset and has that stretch of the row still to sow -- as the plant's tool rule (tool_engagement.h)
  /// keeps the draft on until there.
  bool update(const Eigen::Vector2d& p, bool tool_down, Eigen::Vector2d& seed, bool held_up = false);
  /// The same rule for a seed record: `truth` is the tool point where it really is (it decides the drop, as
  /// update()), `believed` the tool point on the pose the controllers were fed, `depth` the drill's depth
  /// [m]. Returns true and fills `seed` (its row and detour flag from the plan) when a seed falls.
  bool drop(double t, const Eigen::Vector2d& truth, const Eigen::Vector2d& believed, bool tool_down, bool held_up,
            double depth, Seed& seed);
  /// A new plan (the obstacles changed at run time): seeds from now on are scored against it; the
  /// seeds already scored, the distance travelled and the tool's state are kept.
  void setPlan(std::vector<RowSegment> rows, std::vector<Obstacle> obstacles, double influence);

  /// Distance from p to the nearest row segment [m].
  double crossTrack(const Eigen::Vector2d& p) const;
  /// True when p is within engage_distance of a row and between its ends (not beyond them, as in a
  /// headland turn): where the tool may be lowered.
  bool onRowSegment(const Eigen::Vector2d& p) const;
  /// True when p's projection lies strictly between the ends of some row (at any distance from it); past the far
  /// end too when open_ended (the rows go on past their ends: the tool rule's open-ended plan, tool_engagement.h).
  bool withinRowSpan(const Eigen::Vector2d& p, bool open_ended = false) const;
  /// True when p lies in an obstacle's detour zone.
  bool inDetour(const Eigen::Vector2d& p) const;
  /// Index of the row nearest p (-1 without rows).
  int nearestRow(const Eigen::Vector2d& p) const;
  /// Radius of an obstacle's detour zone: radius + influence + detour_margin [m]. Seeds inside it are detour seeds,
  /// whose offset from the row line is reported apart (the robot is going round there).
  double detourRadius(const Obstacle& o) const { return o.radius + influence_ + params_.detour_margin; }
  /// Radius about an obstacle inside which its row is blocked: radius + influence [m]. The plan keeps the axle at
  /// least the influence distance from the obstacle's surface (AvoidanceParams::pathClearance), so no seed can
  /// fall on the row line there; the rest of a detour, where the robot leaves and rejoins the row, is row to sow.
  double blockedRadius(const Obstacle& o) const { return o.radius + influence_; }

  const std::vector<RowSegment>& rows() const { return rows_; }
  const std::vector<Obstacle>& obstacles() const { return obstacles_; }
  const SeedingParams& params() const { return params_; }

  const SeedStats& onRows() const { return rows_stats_; }     ///< seeds away from obstacles
  const SeedStats& detours() const { return detour_stats_; }  ///< seeds in detour zones
  std::string report() const;
  std::size_t rejected() const { return rejected_; }
  /// The drill is down (lowered by update() and not lifted since).
  bool lowered() const { return lowered_; }

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
