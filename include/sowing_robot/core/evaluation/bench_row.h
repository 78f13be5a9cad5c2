// What the benchmark's two row writers share (benchmark.cpp for the ideal loop, estimated_bench.cpp for
// the loop with sensors and an estimate): the numbers of the CSV and of the report, the lateral error,
// the per-period figures of a row and its failure reasons, so that a row means the same whichever loop
// made it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "sowing_robot/core/evaluation/benchmark.h"
#include "sowing_robot/core/evaluation/seed_metrics.h"
#include "sowing_robot/core/model/contact.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/field_path_follower.h"
#include "sowing_robot/core/simulation/field_run.h"
#include "sowing_robot/core/simulation/runner.h"
#include "sowing_robot/core/simulation/seed_recorder.h"

namespace sowing_robot {
namespace core {

/// %.17g: a double that reads back to the same bits (runs.csv).
std::string csvNumber(double v);
/// %.4g (report.md).
std::string shortNumber(double v);

/// Periods between two samples of a scenario's cross-track series (its envelope_period, at least 1).
inline std::int64_t seriesEvery(const BenchScenario& bench) {
  return static_cast<std::int64_t>(
      std::max(1.0, std::round(bench.envelope_period / secondsFromNanos(bench.base.control_period_ns))));
}

/// Per-run extras of a benchmark scenario: the body checked against obstacles, the cross-track series.
struct RunExtras {
  ContactMonitor* contacts = nullptr;  ///< field tracks: the body against the obstacles
  std::int64_t series_every = 0;       ///< sample the cross-track every this many periods (0: none)
  Pose2D* last_reference = nullptr;    ///< gets the last reference pose (the finish check)
  /// Tracks with rows: the plan the run's seed record is sown against (a fresh drill) and the seed-drop point in
  /// base_link; null: no seed record (its figures NaN).
  const SeedDrill* seed_plan = nullptr;
  Eigen::Vector2d tool{-0.45, 0.0};
  bool keep_seeds = false;  ///< the seeds themselves into RunRow::seed_record
};

/// A failure that a run's own end explains better: a performance verdict (cross-track under the tracking rule, the
/// seed record's under the sown rule) yields to "not finished" and "no traction".
inline bool performanceFailure(const std::string& failure) {
  return failure == "cross-track" || failure == "row unsown" || failure == "seed spacing" || failure == "off the row" ||
         failure == "seed map" || failure == "slip";
}

/// The sown rule's verdict on the seed figures ("" when they pass; the slip is judged where it is known).
inline std::string seedFailure(const RunRow& row, const MonteCarloSpec& spec) {
  if (!(row.seed_figures.worst_row_share >= spec.min_sown_share)) return "row unsown";
  if (!(row.seed_figures.quality_of_feed >= spec.min_quality_of_feed)) return "seed spacing";
  if (!(row.seed_figures.lateral_p95 <= spec.max_seed_lateral_p95)) return "off the row";
  if (!(row.seed_figures.map_error_rms <= spec.max_map_error_rms)) return "seed map";
  return "";
}

/// A row's figures, fed every period's sample (add(), inline: it runs in the loop's callback), then
/// written into the row with the failure reason (finish()). The effort, chattering and cross-track are a
/// RunTally (runner.h): a run with neither contacts nor a last reference to follow needs nothing else per
/// period and can give the loop tally() instead of a callback (benchmark.cpp's measure()).
class RowMeter {
 public:
  RowMeter(RunRow& row, const Scenario& sc, const MonteCarloSpec& spec, const RunExtras& extras)
      : row_(row), spec_(spec), extras_(extras), dt_(secondsFromNanos(sc.control_period_ns)) {
    tally_.dt = dt_;
    tally_.settle_time = spec.settle_time;
    tally_.series_every = extras.series_every;
    tally_.series = &row.cross_track_series;
    if (extras.series_every > 0)
      row.cross_track_series.reserve(static_cast<std::size_t>(sc.steps() / extras.series_every + 1));
    if (extras.seed_plan != nullptr) seeds_.emplace(*extras.seed_plan, extras.tool);
  }

  /// Whether add() does more per period than tally().add() (the body against obstacles, the last
  /// reference): then the loop must call add().
  bool needsEveryPeriod() const {
    return extras_.contacts != nullptr || extras_.last_reference != nullptr || extras_.seed_plan != nullptr;
  }
  /// The per-period figures, for runClosedLoop(scenario, reference, keep_samples, tally) when
  /// !needsEveryPeriod(); finish() reads them either way.
  RunTally& tally() { return tally_; }

  void add(const LoopSample& s) {
    addPeriod(s);
    if (seeds_) seeds_->add(s);
  }
  /// A period of the loop with a feedback source and layers: the seeds from the fed pose and the hitch.
  void add(const EstimatedSample& s) {
    addPeriod(*s.loop);
    if (seeds_) seeds_->add(s);
  }

  /// The run's metrics, time at the limit, cross-track, body and end distance into the row, and its
  /// failure: diverged, else contact, else cross-track (the finish check comes after: markNotFinished).
  void finish(const RunResult& r) {
    row_.metrics = r.metrics;
    row_.effort = tally_.effort;
    row_.chattering = tally_.chattering;
    row_.time_at_limit = dt_ * static_cast<double>(r.saturated_steps);
    row_.worst_cross_track = tally_.worst_cross_track;
    row_.final_cross_track = tally_.last_cross_track;
    row_.diverged = r.diverged;
    row_.min_clearance = std::numeric_limits<double>::quiet_NaN();
    if (extras_.last_reference)
      row_.end_distance =
          std::hypot(r.final_state[X] - extras_.last_reference->x, r.final_state[Y] - extras_.last_reference->y);
    if (extras_.contacts) {
      extras_.contacts->finish();
      row_.contacts = extras_.contacts->contactCount();
      row_.min_clearance = extras_.contacts->minClearance();
    }
    if (r.diverged) {
      const double inf = std::numeric_limits<double>::infinity();
      row_.effort = row_.chattering = row_.worst_cross_track = row_.final_cross_track = inf;
      row_.failure = "diverged";
    } else if (row_.contacts > 0) {
      row_.failure = "contact";
    }
    if (seeds_) {
      row_.seed_figures = seedFigures(seeds_->seeds(), seeds_->drill(), &seeds_->passes());
      if (extras_.keep_seeds) row_.seed_record = seeds_->takeSeeds();
    }
    if (row_.failure.empty()) {
      if (spec_.rule == SuccessRule::tracking || !seeds_) {
        if (!(tally_.worst_cross_track < spec_.cross_track_threshold)) row_.failure = "cross-track";
      } else {
        row_.failure = seedFailure(row_, spec_);
      }
    }
    row_.success = row_.failure.empty();
  }

 private:
  void addPeriod(const LoopSample& s) {
    tally_.add(s);
    if (extras_.contacts) extras_.contacts->update(s.t, {(*s.state)[X], (*s.state)[Y], (*s.state)[THETA]});
    if (extras_.last_reference) *extras_.last_reference = s.reference->pose;
  }

  RunRow& row_;
  const MonteCarloSpec& spec_;
  const RunExtras& extras_;
  const double dt_;
  RunTally tally_;
  std::optional<SeedRecorder> seeds_;
};

/// The row a line track's seeds are judged on: the line between the reference's positions at settle_time and 2 s
/// before the end (the approach to the line is not a row, and at the end the tool point trails the target by its
/// 0.45 m behind the axle plus the tracking lag), sown against no obstacles.
inline SeedDrill lineSeedPlan(const BenchScenario& bench) {
  const double from = bench.line_x0 + bench.line_v_r * bench.spec.settle_time;
  const double to = bench.line_x0 + bench.line_v_r * std::max(bench.spec.settle_time, bench.base.duration - 2.0);
  return SeedDrill(bench.realism ? bench.realism->seeding : SeedingParams(),
                   {RowSegment{Eigen::Vector2d(from, bench.line_y), Eigen::Vector2d(to, bench.line_y)}}, {}, 0.0);
}

/// A field run's finish check: not finished when the plan stops short of a row end, the path had not
/// ended, or the robot is not within `tolerance` of its end. A contact or a divergence is the reason
/// given before this one; a cross-track failure comes after. The path's end is checked at the time the
/// reference was last asked for (ReferenceSource::lastTime()), not the run's duration: a speed governor
/// slows the path's own time, and a robot close to a slowed target that is still short of the path's
/// end has not finished.
inline void markNotFinished(RunRow& row, const FieldSource& reference, double duration, double tolerance) {
  if (!row.failure.empty() && !performanceFailure(row.failure)) return;
  const bool stopped = reference.status().code != AvoidanceStatus::Code::kOk;
  const bool ended = reference.finished(std::min(duration, reference.lastTime()));
  if (stopped || !ended || !(row.end_distance < tolerance)) {
    row.failure = "not finished";
    row.success = false;
  }
}

/// A field row as run_scenario --field runs it: the path from the drawn start (the approach), the run's
/// duration grown by the approach's extra time, the body followed against the obstacles, the finish checked.
/// `measure(scenario, reference, extras)` runs the row (benchmark.cpp's measure, estimated_bench.cpp's
/// measureEstimated).
template <typename Measure>
RunRow fieldRow(const BenchScenario& bench, Scenario sc, RunExtras extras, Measure measure) {
  FieldParams field = bench.field;
  field.start_pose = sc.start;
  const std::unique_ptr<FieldSource> source = makeFieldSource(field, bench.obstacles);
  FieldSource& reference = *source;
  sc.duration += approachExtraTime(reference);  // from the reference built: the path follower's costs ~8 ms
  ContactMonitor contacts(bench.footprint, bench.obstacles);
  Pose2D last_ref;
  extras.contacts = &contacts;
  extras.last_reference = &last_ref;
  const SeedDrill plan(bench.realism ? bench.realism->seeding : SeedingParams(), rowsOf(bench.field), bench.obstacles,
                       bench.field.potential.influence_distance);
  extras.seed_plan = &plan;
  if (bench.realism) extras.tool = bench.realism->tool;
  RunRow row = measure(sc, reference, extras);
  markNotFinished(row, reference, sc.duration, bench.finish_tolerance);
  return row;
}

}  // namespace core
}  // namespace sowing_robot
