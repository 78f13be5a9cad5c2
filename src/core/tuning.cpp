#include "sowing_robot/core/tuning.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <stdexcept>
#include <thread>

#include "sowing_robot/core/validation.h"

namespace sowing_robot {
namespace core {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

/// A tunable entry of the Kanayama or the sliding-mode table (the `tunable` mark in their tables).
template <typename S>
const ParamEntry<S>* tunableEntry(const ParamTable<S>& table, const std::string& name) {
  const ParamEntry<S>* e = table.find(name);
  return e && e->info.tunable ? e : nullptr;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

/// Effort and chattering of one run, accumulated by the runner's trace (no allocation per step).
struct TorqueTally {
  double effort = 0.0, chattering = 0.0;
  double last_t = 0.0, last_r = 0.0, last_l = 0.0;
  bool any = false;
  void add(const LoopSample& s) {
    const double r = s.control->torques.right, l = s.control->torques.left;
    if (any) {
      // The previous command was held over [last_t, t] (zero-order hold, as the plant applies it).
      effort += (last_r * last_r + last_l * last_l) * (s.t - last_t);
      chattering += std::fabs(r - last_r) + std::fabs(l - last_l);
    }
    any = true;
    last_t = s.t;
    last_r = r;
    last_l = l;
  }
};

}  // namespace

bool parseCostType(const std::string& name, CostType& out) {
  if (name == "itae")
    out = CostType::ITAE;
  else if (name == "ise")
    out = CostType::ISE;
  else if (name == "iae")
    out = CostType::IAE;
  else if (name == "itse")
    out = CostType::ITSE;
  else
    return false;
  return true;
}

const char* costTypeName(CostType type) {
  switch (type) {
    case CostType::ITAE: return "itae";
    case CostType::ISE: return "ise";
    case CostType::IAE: return "iae";
    case CostType::ITSE: return "itse";
  }
  return "?";
}

const std::vector<std::string>& tunableGainNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& e : kanayamaTable().entries())
      if (e.info.tunable) n.push_back(e.info.key);
    for (const auto& e : slidingModeTable().entries())
      if (e.info.tunable) n.push_back(e.info.key);
    return n;
  }();
  return names;
}

std::string gainNode(const std::string& name) {
  if (tunableEntry(kanayamaTable(), name)) return "kinematic_controller";
  if (tunableEntry(slidingModeTable(), name)) return "torque_controller";
  return "";
}

bool setGain(Scenario& sc, const std::string& name, double value) {
  if (const auto* e = tunableEntry(kanayamaTable(), name)) {
    e->set(sc.kanayama, value);
    return true;
  }
  if (const auto* e = tunableEntry(slidingModeTable(), name)) {
    e->set(sc.sliding, value);
    return true;
  }
  return false;
}

double getGain(const Scenario& sc, const std::string& name) {
  if (const auto* e = tunableEntry(kanayamaTable(), name)) return std::get<double>(e->get(sc.kanayama));
  if (const auto* e = tunableEntry(slidingModeTable(), name)) return std::get<double>(e->get(sc.sliding));
  return std::numeric_limits<double>::quiet_NaN();
}

std::vector<GainBounds> defaultGainBounds() {
  return {{"kx", 0.1, 10.0},   {"ky", 0.1, 10.0},   {"ktheta", 0.1, 10.0}, {"k1", 0.1, 1000.0},
          {"k2", 0.1, 1000.0}, {"eta1", 0.1, 10.0}, {"eta2", 0.1, 10.0}};
}

std::string validateGainBounds(const Scenario& base, const std::vector<GainBounds>& gains) {
  if (gains.empty()) return "gains is empty: give at least one {name, lower, upper} to tune";
  for (std::size_t i = 0; i < gains.size(); ++i) {
    const GainBounds& g = gains[i];
    const std::string at = "gains[" + std::to_string(i) + "] (" + g.name + ")";
    if (gainNode(g.name).empty()) {
      std::string known;
      for (const auto& n : tunableGainNames()) known += (known.empty() ? "" : ", ") + n;
      return at + ": unknown gain '" + g.name + "' (tunable: " + known + ")";
    }
    for (std::size_t j = 0; j < i; ++j)
      if (gains[j].name == g.name)
        return at + ": '" + g.name + "' is listed twice (also gains[" + std::to_string(j) + "])";
    if (!allFinite(g.lower, g.upper))
      return at + ": bounds must be finite numbers, got lower = " + num(g.lower) + ", upper = " + num(g.upper);
    if (!(g.lower < g.upper)) return at + ": lower = " + num(g.lower) + " must be < upper = " + num(g.upper);
  }
  // Every constraint validate() puts on one of these gains is an interval, so the two corners suffice.
  for (int corner = 0; corner < 2; ++corner) {
    Scenario sc = base;
    for (const auto& g : gains) setGain(sc, g.name, corner == 0 ? g.lower : g.upper);
    const std::string e = firstError({sc.kanayama.validate(), sc.sliding.validate()});
    if (!e.empty())
      return std::string("gains: with every gain at its ") + (corner == 0 ? "lower" : "upper") +
             " bound the controller refuses it: " + e;
  }
  return "";
}

std::string TuningObjective::validate() const {
  return firstError(
      {checkNonNegative("torque_weight", torque_weight), checkNonNegative("chattering_weight", chattering_weight)});
}

TuningProblem::TuningProblem(const Scenario& base, const ReferenceSource& reference, std::vector<GainBounds> gains,
                             const TuningObjective& objective, int threads)
    : base_(base), gains_(std::move(gains)), objective_(objective) {
  for (int t = 0; t < std::max(threads, 1); ++t) references_.push_back(reference.clone());
}

Scenario TuningProblem::scenarioFor(const std::vector<double>& x) const {
  Scenario sc = base_;
  for (std::size_t d = 0; d < gains_.size() && d < x.size(); ++d) setGain(sc, gains_[d].name, x[d]);
  return sc;
}

void TuningProblem::total(const std::array<AxisMetrics, AXIS_COUNT>& metrics, double effort, double chattering,
                          TuningCost& c) const {
  c.tracking = 0.0;
  for (const AxisMetrics& m : metrics) {
    switch (objective_.cost) {
      case CostType::ITAE: c.tracking += m.itae; break;
      case CostType::ISE: c.tracking += m.ise; break;
      case CostType::IAE: c.tracking += m.iae; break;
      case CostType::ITSE: c.tracking += m.itse; break;
    }
  }
  c.effort = effort;
  c.chattering = chattering;
  c.total = c.tracking;
  if (objective_.torque_weight > 0.0) c.total += objective_.torque_weight * c.effort;
  if (objective_.chattering_weight > 0.0) c.total += objective_.chattering_weight * c.chattering;
}

TuningCost TuningProblem::evaluate(const std::vector<double>& x, int thread_index, double bound) const {
  const Scenario sc = scenarioFor(x);
  ReferenceSource& ref = *references_.at(static_cast<std::size_t>(thread_index));
  TorqueTally tally;
  const bool traced = objective_.torque_weight > 0.0 || objective_.chattering_weight > 0.0;
  std::function<void(const LoopSample&)> trace;
  if (traced) {
    TorqueTally* t = &tally;  // one pointer: fits std::function's small buffer, no allocation
    trace = [t](const LoopSample& s) { t->add(s); };
  }
  RunStop stop;
  if (std::isfinite(bound)) {
    stop = [this, &tally, bound](const MetricsAccumulator& m) {
      TuningCost partial;
      total(m.result(), tally.effort, tally.chattering, partial);
      return partial.total >= bound;
    };
  }
  const RunResult r = runClosedLoop(sc, ref, false, trace, stop);

  TuningCost c;
  c.diverged = r.diverged;
  c.bounded = r.stopped;
  c.simulated = secondsFromNanos(r.periods * sc.control_period_ns);
  total(r.metrics, tally.effort, tally.chattering, c);
  if (r.diverged || !std::isfinite(c.total)) c.total = INF;
  return c;
}

int psoThreads(const PsoParams& p) {
  int threads = p.threads > 0 ? p.threads : static_cast<int>(std::thread::hardware_concurrency());
  return std::clamp(threads, 1, std::max(p.particles, 1));
}

TuningResult tuneGains(const Scenario& base, const ReferenceSource& reference, const std::vector<GainBounds>& gains,
                       const TuningObjective& objective, PsoParams params, const PsoProgressCallback& progress) {
  std::string e = firstError({base.validate(), validateGainBounds(base, gains), objective.validate()});
  if (!e.empty()) throw std::invalid_argument(e);
  params.lower.clear();
  params.upper.clear();
  for (const auto& g : gains) {
    params.lower.push_back(g.lower);
    params.upper.push_back(g.upper);
  }
  e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);

  TuningResult out;
  out.threads = psoThreads(params);
  const TuningProblem problem(base, reference, gains, objective, out.threads);
  const auto t0 = std::chrono::steady_clock::now();
  // Bounded: a particle's run stops once it cannot beat its personal best (same search, less work).
  std::atomic<long> cut{0};
  std::atomic<std::int64_t> simulated_ns{0};
  out.pso = psoMinimize(params, PsoBoundedFitness([&](const std::vector<double>& x, int thread, double bound) {
                          const TuningCost c = problem.evaluate(x, thread, bound);
                          if (c.bounded) ++cut;
                          simulated_ns += std::llround(c.simulated * 1e9);
                          return c.total;
                        }),
                        progress);
  out.evaluations_cut = cut;
  out.simulated_s = 1e-9 * static_cast<double>(simulated_ns.load());
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.best_gains = out.pso.best_position;
  out.best = problem.evaluate(out.best_gains, 0);
  out.initial_best_cost = out.pso.best_cost_per_iteration.empty() ? INF : out.pso.best_cost_per_iteration.front();
  return out;
}

}  // namespace core
}  // namespace sowing_robot
