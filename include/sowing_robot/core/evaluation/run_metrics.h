// The benchmark's per-run metrics, one entry each: its runs.csv column, unit, meaning, how a run's row gives it
// (and takes it back), and how runs aggregate. Everything that names a metric is derived from this list:
// runs.csv's metric columns and values (benchmark.cpp), the report's per-metric table and overview, the MPI
// farm's packed row (packRow/unpackRow), DIR/metrics.json that benchmark_plots reads for its box plots, sweep
// plots and comparison, and sowing_robot.core.run_metrics(). The tracking integrals per axis come from
// axisFigures() (simulation/metrics.h: also the metrics YAML of run_monitor and the Python metrics dicts).
//
// Adding a metric: a field in RunRow (benchmark.h) and the code that computes it (RowMeter::finish in
// bench_row.h, or measureEstimated in estimated_bench.cpp for a realism one), then ONE entry in
// runMetrics() (run_metrics.cpp). test_benchmark fails on a runs.csv column without an entry.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "sowing_robot/core/evaluation/benchmark.h"

namespace sowing_robot {
namespace core {

/// How runs.csv writes a value: %.17g (csvNumber), an integer, or 0/1.
enum class MetricFormat { number, count, flag };
/// Which runs.csv block the column is in: always, or only in files with a realism scenario (sensors, traction
/// or an estimate in the loop: after sensor_seed; on a row without realism a number is "nan", a count empty).
enum class MetricGroup { always, realism };
/// The figure a comparison of controller pairs reads over a batch of runs (benchmark_plots' comparison.md):
/// the median, the mean, or the share of runs where the value is true (a flag; compared by whole runs).
enum class Aggregation { median, mean, share };
/// Which direction is better (the comparison; none: not compared).
enum class Better { lower, higher, none };
/// benchmark_plots' figures of a metric (bits): a box per controller, or a scatter against the amplitude of
/// *sweep scenarios.
enum MetricPlot : unsigned { kNoPlot = 0, kBoxPlot = 1, kSweepPlot = 2 };

/// One per-run metric.
struct RunMetric {
  std::string name;     ///< runs.csv column (and metrics.json / run_metrics() key)
  std::string unit;     ///< "1" for a ratio, "bool" for a flag, what is counted for a count
  std::string label;    ///< short name in figures, the overview and the comparison ("worst cross-track")
  std::string meaning;  ///< one line
  std::function<double(const RunRow&)> get;  ///< the run's value (counts and flags as doubles: exact)
  std::function<void(RunRow&, double)> set;  ///< get's inverse (unpackRow)
  MetricFormat format = MetricFormat::number;
  MetricGroup group = MetricGroup::always;
  bool report_table = false;  ///< a row of the report's per-metric table (mean, std, p95, worst)
  /// The report's overview (one line per scenario and controller): its column there (1, 2, ...; 0: not in it),
  /// the mean over the runs, and the p95 too when overview_p95.
  int overview_column = 0;
  bool overview_p95 = false;
  Aggregation aggregation = Aggregation::median;
  Better better = Better::lower;
  bool compared = false;  ///< in benchmark_plots' comparison of pairs
  unsigned plots = kNoPlot;
  bool seed_figure = false;  ///< one of the seed record's figures (SeedFigures: what Python's seed_figures holds)
};

/// Every per-run metric, in runs.csv order within its group.
const std::vector<RunMetric>& runMetrics();

/// runs.csv's columns that are not metrics: who ran (scenario, its evaluation set, controller), what was drawn (seed
/// and draws, sensor_seed in the realism block), and why a run failed (failure, text).
const std::vector<std::string>& runsCsvIdentityColumns();

/// The registry as JSON (a list of objects, one per metric: name, unit, label, meaning, format, group,
/// aggregation, better, compared, plots, report_table, overview_column, overview_p95), what the benchmark writes to
/// DIR/metrics.json.
std::string runMetricsJson();

}  // namespace core
}  // namespace sowing_robot
