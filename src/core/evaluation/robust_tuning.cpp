#include "sowing_robot/core/evaluation/robust_tuning.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

std::string RobustObjective::validate() const {
  if (!(failure_penalty > 0.0 && std::isfinite(failure_penalty)))
    return "robust/failure_penalty must be finite and > 0, not " + std::to_string(failure_penalty);
  if (aggregate == Aggregate::quantile && !(quantile > 0.0 && quantile <= 1.0))
    return "robust/quantile must be in (0, 1], not " + std::to_string(quantile);
  if (!(max_slip_share > 0.0 && max_slip_share <= 1.0))
    return "robust/max_slip_share must be in (0, 1], not " + std::to_string(max_slip_share);
  return "";
}

bool parseAggregate(const std::string& name, RobustObjective::Aggregate& out) {
  if (name == "mean")
    out = RobustObjective::Aggregate::mean;
  else if (name == "quantile")
    out = RobustObjective::Aggregate::quantile;
  else
    return false;
  return true;
}

double trainingRunCost(const RunRow& row, double duration, const RobustObjective& objective) {
  double itae = 0.0;
  for (const AxisMetrics& m : row.metrics) itae += m.itae;
  double tracking = 2.0 * itae / (duration * duration);
  // A diverged run's non-finite ITAE, like any too large one, costs the cap.
  if (!(tracking < objective.failure_penalty)) tracking = objective.failure_penalty;
  // A run without the traction plant has no slip share (NaN): only the benchmark's rule judges it.
  const bool slipped = objective.max_slip_share < 1.0 && row.high_slip_share > objective.max_slip_share;
  return tracking + (row.success && !slipped ? 0.0 : objective.failure_penalty);
}

RobustTuningProblem::RobustTuningProblem(std::vector<TrainingScenario> set, std::vector<GainBounds> gains,
                                         const RobustObjective& objective, int threads)
    : set_(std::move(set)), gains_(std::move(gains)), objective_(objective), threads_(std::max(threads, 1)) {
  std::string e = objective_.validate();
  if (e.empty() && set_.empty()) e = "the training set is empty";
  for (const TrainingScenario& t : set_) {
    if (!e.empty()) break;
    if (t.runs < 1) e = t.bench.name + ": runs must be >= 1";
    if (e.empty()) e = t.bench.validate();
    if (e.empty()) e = validateGainBounds(t.bench.base, gains_);
    if (!e.empty() && e.rfind(t.bench.name, 0) != 0) e = t.bench.name + ": " + e;
    run_count_ += t.runs;
  }
  if (!e.empty()) throw std::invalid_argument(e);
}

std::pair<std::size_t, std::int64_t> RobustTuningProblem::locate(std::int64_t k) const {
  if (k < 0 || k >= run_count_) throw std::out_of_range("training run " + std::to_string(k) + " out of range");
  std::size_t s = 0;
  while (k >= set_[s].runs) k -= set_[s++].runs;
  return {s, k};
}

BenchScenario RobustTuningProblem::withGains(std::size_t scenario, const std::vector<double>& position) const {
  BenchScenario b = set_[scenario].bench;
  for (std::size_t d = 0; d < gains_.size(); ++d) setGain(b.base, gains_[d].name, position.at(d));
  return b;
}

Scenario RobustTuningProblem::scenarioFor(const std::vector<double>& position) const {
  return withGains(0, position).base;
}

RunRow RobustTuningProblem::runRow(const std::vector<double>& position, std::int64_t k) const {
  const auto [s, i] = locate(k);
  return benchmarkWorker(withGains(s, position))(i);
}

double RobustTuningProblem::runCost(const std::vector<double>& position, std::int64_t k) const {
  return trainingRunCost(runRow(position, k), set_[locate(k).first].bench.base.duration, objective_);
}

TuningCost RobustTuningProblem::combine(const std::vector<double>& run_costs) const {
  TuningCost c;
  if (objective_.aggregate == RobustObjective::Aggregate::mean) {
    double sum = 0.0;
    for (double v : run_costs) sum += v;  // in run order: the same bits wherever the runs ran
    c.total = sum / static_cast<double>(run_costs.size());
  } else {
    std::vector<double> sorted = run_costs;
    std::sort(sorted.begin(), sorted.end());
    const auto rank = static_cast<std::size_t>(std::ceil(objective_.quantile * static_cast<double>(sorted.size())));
    c.total = sorted[std::max<std::size_t>(rank, 1) - 1];
  }
  c.tracking = c.total;
  for (std::size_t s = 0, k = 0; s < set_.size(); ++s)
    for (std::int64_t i = 0; i < set_[s].runs && k < run_costs.size(); ++i, ++k)
      c.simulated += set_[s].bench.base.duration;
  return c;
}

TuningCost RobustTuningProblem::evaluate(const std::vector<double>& position, int /*thread_index*/,
                                         double bound) const {
  std::vector<double> costs;
  costs.reserve(static_cast<std::size_t>(run_count_));
  const bool may_stop = objective_.aggregate == RobustObjective::Aggregate::mean && std::isfinite(bound);
  double sum = 0.0;
  for (std::int64_t k = 0; k < run_count_; ++k) {
    costs.push_back(runCost(position, k));
    sum += costs.back();
    if (may_stop && k + 1 < run_count_ && sum / static_cast<double>(run_count_) >= bound) {
      TuningCost c = combine(costs);                    // simulated: the runs so far
      c.total = sum / static_cast<double>(run_count_);  // the whole set's mean is at least this, >= bound
      c.tracking = c.total;
      c.bounded = true;
      return c;
    }
  }
  return combine(costs);
}

std::string RobustTuningProblem::describeSet() const {
  std::string out;
  for (const TrainingScenario& t : set_) {
    if (!out.empty()) out += ", ";
    out += t.bench.name + " runs 0-" + std::to_string(t.runs - 1) + " of base seed " +
           std::to_string(t.bench.spec.base_seed);
  }
  return out;
}

}  // namespace core
}  // namespace sowing_robot
