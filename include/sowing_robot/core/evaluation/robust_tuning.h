// Robust gain tuning: the PSO of tuning.h scoring each gain vector over a training set
// of benchmark runs (scenarios x seeded draws: soils, patches, drafts, mismatch, start poses, feedback)
// instead of one run on the thesis line. Every run is the benchmark's own (benchmarkWorker), so a training
// run and a benchmark row of the same scenario and draw are the same bits.
//
// The cost of one run is bounded and finite, so one hopeless run cannot swamp the search and the swarm
// always has a best:
//   run cost = min(2 (ITAE_x + ITAE_y + ITAE_theta) / T^2, failure_penalty) + failure_penalty [not a success]
// where T is the scenario's duration: 2 ITAE / T^2 is the time-weighted mean error (ITAE of a constant
// error e is e T^2 / 2), in m (+ rad), comparable across scenarios of different length. A failure
// (diverged, body contact, not finished, cross-track above the threshold after the settle time: the
// benchmark's success rule) costs the penalty on top, so the search first buys successes, then accuracy.
// With max_slip_share < 1 a run whose wheels spent more than that share of it beyond twice the friction
// peak's slip (RunRow::high_slip_share: the slip target "within 2x the peak for 95 % of the run" at 0.05) is
// a failure too: the search then buys runs that meet the slip target, not only the benchmark's success.
// The set's cost is the mean of the run costs, or a chosen quantile (nearest rank) of them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sowing_robot/core/evaluation/benchmark.h"
#include "sowing_robot/core/evaluation/tuning.h"

namespace sowing_robot {
namespace core {

/// One scenario of a training set: runs 0..runs-1 of its Monte-Carlo draws (its spec.base_seed).
struct TrainingScenario {
  BenchScenario bench;  ///< with the pair being tuned (withController)
  std::int64_t runs = 1;
};

struct RobustObjective {
  enum class Aggregate { mean, quantile };
  Aggregate aggregate = Aggregate::mean;
  double quantile = 0.9;         ///< for Aggregate::quantile, in (0, 1]
  double failure_penalty = 1.0;  ///< added per failed run, and the cap of the tracking term [m] (> 0)
  double max_slip_share = 1.0;   ///< a run beyond twice the peak's slip longer than this share fails; 1 = off

  std::string validate() const;
};
/// "mean" | "quantile" -> aggregate; false if unknown.
bool parseAggregate(const std::string& name, RobustObjective::Aggregate& out);

/// The cost of one benchmark row as above (duration: the scenario's base duration T [s]).
double trainingRunCost(const RunRow& row, double duration, const RobustObjective& objective);

/// The training set's cost of gain vectors (in the order of `gains`). evaluate() runs the whole set in
/// order on the calling thread; runCost() runs one of its runs, so a farm can hand runs out one by one
/// and combine() them: the same number either way. Thread-safe (no state shared between calls).
class RobustTuningProblem : public GainObjective {
 public:
  /// Throws std::invalid_argument (one line) for an empty set, runs < 1, a scenario that does not
  /// validate, bad gain bounds for a scenario's pair, or a bad objective.
  RobustTuningProblem(std::vector<TrainingScenario> set, std::vector<GainBounds> gains,
                      const RobustObjective& objective, int threads);

  const std::vector<GainBounds>& gains() const override { return gains_; }
  /// The first training scenario's controller settings with the gains applied.
  Scenario scenarioFor(const std::vector<double>& position) const override;
  /// The whole set. With the mean and a finite bound, stops once the runs so far (each cost >= 0) put
  /// the mean at or above the bound (bounded set, total = that lower bound).
  TuningCost evaluate(const std::vector<double>& position, int thread_index,
                      double bound = std::numeric_limits<double>::infinity()) const override;
  int threads() const override { return threads_; }

  /// Total runs in the set; run k is scenario s's run i in the set's order (s by s, i ascending).
  std::int64_t runCount() const { return run_count_; }
  /// The benchmark row of run k with these gains.
  RunRow runRow(const std::vector<double>& position, std::int64_t k) const;
  /// trainingRunCost of run k with these gains.
  double runCost(const std::vector<double>& position, std::int64_t k) const;
  /// The set's cost from every run's cost (in run order); simulated = the runs' scenario durations.
  TuningCost combine(const std::vector<double>& run_costs) const;

  const std::vector<TrainingScenario>& set() const { return set_; }
  const RobustObjective& objective() const { return objective_; }
  /// One line: "NAME runs 0-N of base seed S, ..." (what the gains file's header records).
  std::string describeSet() const;

 private:
  std::vector<TrainingScenario> set_;
  std::vector<GainBounds> gains_;
  RobustObjective objective_;
  int threads_ = 1;
  std::int64_t run_count_ = 0;

  /// Scenario index and run index of run k.
  std::pair<std::size_t, std::int64_t> locate(std::int64_t k) const;
  BenchScenario withGains(std::size_t scenario, const std::vector<double>& position) const;
};

}  // namespace core
}  // namespace sowing_robot
