#include "sowing_robot/core/evaluation/tuning.h"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <thread>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

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

namespace {

const char* const kKinematicNode = "kinematic_controller";
const char* const kTorqueNode = "torque_controller";
// Every controller's parameters sit flat under its node (the nodes' keys: kinematic_controller/lookahead_dist,
// torque_controller/kp), so a gains YAML loads into the nodes as it is (sim.launch gains:=). No key of one
// table is in another's of the same slot, except max_torque: the motor's one limit, which sets both.

/// A tunable gain of the scenario's pair: its table entry, node, key prefix and the struct it sets.
struct GainRef {
  const ParamInfo* info = nullptr;
  const char* node = "";
  const char* prefix = "";
  std::function<void(Scenario&, double)> set;
  std::function<double(const Scenario&)> get;
};

/// Every tunable gain of the scenario's pair that acts in it (controller_factory.h), outer's then inner's,
/// in table order.
std::vector<GainRef> pairGains(const Scenario& sc) {
  std::vector<GainRef> out;
  for (const ControllerParam& p : chosenControllerParams(sc)) {
    if (!p.info->tunable || !p.acts(sc, p.info->key)) continue;
    GainRef g;
    g.info = p.info;
    g.node = p.slot == ControllerParam::Slot::outer ? kKinematicNode : kTorqueNode;
    g.set = [set = p.set](Scenario& s, double v) { set(s, v); };
    g.get = [get = p.get](const Scenario& s) { return std::get<double>(get(s)); };
    out.push_back(std::move(g));
  }
  return out;
}

bool findGain(const Scenario& sc, const std::string& name, GainRef& out) {
  for (auto& g : pairGains(sc))
    if (g.info->key == name) {
      out = std::move(g);
      return true;
    }
  return false;
}

/// Search bounds of every tunable mark, one row per gain (gainSearchBounds' comment gives the reasons).
const std::vector<GainBounds>& searchBoundsList() {
  static const std::vector<GainBounds> list = {
      // Kanayama: [0.1, 10], since the thesis default ktheta = 2.2 is already outside Table 5.4's [0.1, 2].
      {"kx", 0.1, 10.0},
      {"ky", 0.1, 10.0},
      {"ktheta", 0.1, 10.0},
      // Sliding mode: Table 5.4 (beta [0.1, 2], K [0.1, 1000]); eta spans the 2.75 N·m disturbance.
      {"beta_v", 0.1, 2.0},
      {"beta_omega", 0.1, 2.0},
      {"k1", 0.1, 1000.0},
      {"k2", 0.1, 1000.0},
      {"eta1", 0.1, 10.0},
      {"eta2", 0.1, 10.0},
      {"rate_m", 0.0, 10.0},
      {"rate_i", 0.0, 10.0},
      // Pure pursuit / RPP: nav2's lookahead range; the along-track feedback up to Kanayama's kx range.
      {"lookahead_dist", 0.3, 0.9},
      {"regulated_linear_scaling_min_radius", 0.1, 3.0},
      {"k_along", 0.0, 10.0},
      // Wheel PID (wheel-speed error in rad/s, 1 m/s ~ 10.5 rad/s): up to ~25x the defaults 2 and 20.
      {"kp", 0.0, 50.0},
      {"ki", 0.0, 500.0},
      {"kd", 0.0, 0.5},
      {"feedforward", 0.0, 2.0},
  };
  return list;
}

/// Set one entry of `table` (in `params`) from a key and a value: "" or the reason.
}  // namespace

std::vector<std::string> tunableGainNames(const Scenario& sc) {
  std::vector<std::string> names;
  for (const auto& g : pairGains(sc)) names.push_back(g.info->key);
  return names;
}

const std::vector<std::string>& tunableGainNames() {
  static const std::vector<std::string> names = tunableGainNames(Scenario());
  return names;
}

std::string gainNode(const Scenario& sc, const std::string& name) {
  GainRef g;
  return findGain(sc, name, g) ? g.node : "";
}

std::string gainKey(const Scenario& sc, const std::string& name) {
  GainRef g;
  return findGain(sc, name, g) ? std::string(g.prefix) + name : "";
}

bool setGain(Scenario& sc, const std::string& name, double value) {
  GainRef g;
  if (!findGain(sc, name, g)) return false;
  g.set(sc, value);
  return true;
}

double getGain(const Scenario& sc, const std::string& name) {
  GainRef g;
  return findGain(sc, name, g) ? g.get(sc) : std::numeric_limits<double>::quiet_NaN();
}

std::string setControllerParam(Scenario& sc, const std::string& node, const std::string& key, const ParamValue& value) {
  ControllerParam::Slot slot;
  if (node == kKinematicNode)
    slot = ControllerParam::Slot::outer;
  else if (node == kTorqueNode)
    slot = ControllerParam::Slot::inner;
  else
    return "unknown controller node '" + node + "' (kinematic_controller, torque_controller)";
  // Every table of the slot that has the key: max_torque, the motors' one limit, is in both inner tables.
  bool found = false;
  for (const ControllerParam& p : slotParams(slot)) {
    if (p.info->key != key) continue;
    ParamValue v = value;
    // An integer where the table wants a double (YAML "2" for 2.0) is that double.
    if (std::holds_alternative<int>(v) && std::holds_alternative<double>(p.info->default_value))
      v = static_cast<double>(std::get<int>(v));
    const std::string error = p.info->check(v, node + "/");
    if (!error.empty()) return error;
    p.set(sc, v);
    found = true;
  }
  return found ? "" : node + "/" + key + " is no controller parameter";
}

GainBounds gainSearchBounds(const std::string& name) {
  for (const auto& b : searchBoundsList())
    if (b.name == name) return b;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {name, nan, nan};
}

std::vector<GainBounds> defaultGainBounds(const Scenario& sc) {
  std::vector<GainBounds> out;
  for (const auto& name : tunableGainNames(sc)) out.push_back(gainSearchBounds(name));
  return out;
}

std::vector<GainBounds> defaultGainBounds() {
  std::vector<GainBounds> out;
  for (const char* n : {"kx", "ky", "ktheta", "k1", "k2", "eta1", "eta2"}) out.push_back(gainSearchBounds(n));
  return out;
}

std::string yamlFloat(double v) {
  if (std::isnan(v)) return ".nan";
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  char b[64];
  const auto r = std::to_chars(b, b + sizeof b, v);
  std::string s(b, r.ptr);
  if (s.find('.') == std::string::npos) {  // YAML 1.1 needs the dot: "2" is an int, "1e-05" a string
    const auto e = s.find('e');
    if (e == std::string::npos)
      s += ".0";
    else
      s.insert(e, ".0");
  }
  return s;
}

std::string gainsYaml(const Scenario& tuned, const std::vector<GainBounds>& searched) {
  std::string out, node, prefix;
  auto line = [&out](const std::string& indent, const std::string& key, const std::string& value,
                     const std::string& comment) {
    std::string l = indent + key + ": " + value;
    l.resize(std::max<std::size_t>(l.size() + 1, 36), ' ');
    out += l + comment + "\n";
  };
  for (const GainRef& g : pairGains(tuned)) {
    if (g.node != node) {
      node = g.node;
      prefix.clear();
      out += node + ":\n";
    }
    if (g.prefix != prefix) {
      prefix = g.prefix;
      out += "  " + prefix.substr(0, prefix.size() - 1) + ":\n";
    }
    std::string comment = "# base value (not tuned)";
    for (const auto& b : searched)
      if (b.name == g.info->key) comment = "# tuned in [" + num(b.lower) + ", " + num(b.upper) + "]";
    line(prefix.empty() ? "  " : "    ", g.info->key, yamlFloat(g.get(tuned)), comment);
  }
  // The reading the rates were tuned with, when it is not the default (a default file stays gains only).
  if (tuned.inner == InnerKind::sliding_mode && tuned.sliding.adaptive &&
      tuned.sliding.adaptation != Adaptation::mass_inertia) {
    if (node != kTorqueNode) out += std::string(kTorqueNode) + ":\n";
    line("  ", "adaptation", formatValue(slidingModeTable().find("adaptation")->get(tuned.sliding)),
         "# the rates act on gamma_hat, alpha_hat (docs/deviations.md 8)");
  }
  return out;
}

std::string validateGainBounds(const Scenario& base, const std::vector<GainBounds>& gains) {
  if (gains.empty()) return "gains is empty: give at least one {name, lower, upper} to tune";
  for (std::size_t i = 0; i < gains.size(); ++i) {
    const GainBounds& g = gains[i];
    const std::string at = "gains[" + std::to_string(i) + "] (" + g.name + ")";
    if (gainNode(base, g.name).empty()) {
      std::string known;
      for (const auto& n : tunableGainNames(base)) known += (known.empty() ? "" : ", ") + n;
      return at + ": '" + g.name + "' is no tunable gain of " + base.controllerName() + " (tunable: " + known + ")";
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
    const std::string e = sc.validate();
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

TuningBatch threadedTuningBatch(const GainObjective& problem, const PsoParams& params) {
  struct Batch {  // the batch being evaluated, set before each run
    const std::vector<std::vector<double>>* x = nullptr;
    const std::vector<double>* bounds = nullptr;
    std::vector<TuningCost>* out = nullptr;
  };
  auto batch = std::make_shared<Batch>();
  auto run = psoThreadPool(std::min(psoThreads(params), problem.threads()), [batch, &problem](int j, int thread_index) {
    const auto k = static_cast<std::size_t>(j);
    (*batch->out)[k] = problem.evaluate((*batch->x)[k], thread_index, (*batch->bounds)[k]);
  });
  return [batch, run](const std::vector<std::vector<double>>& x, const std::vector<double>& bounds,
                      std::vector<TuningCost>& out) {
    batch->x = &x;
    batch->bounds = &bounds;
    batch->out = &out;
    run(static_cast<int>(x.size()));
  };
}

namespace {
/// The PSO parameters with the box of `gains` (std::invalid_argument, one line, if they do not validate).
PsoParams withBox(PsoParams params, const std::vector<GainBounds>& gains) {
  params.lower.clear();
  params.upper.clear();
  for (const auto& g : gains) {
    params.lower.push_back(g.lower);
    params.upper.push_back(g.upper);
  }
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  return params;
}
}  // namespace

TuningSession::TuningSession(const Scenario& base, const ReferenceSource& reference,
                             const std::vector<GainBounds>& gains, const TuningObjective& objective, PsoParams params,
                             int problem_threads)
    : search_([&]() -> PsoParams {
        const std::string e = firstError({base.validate(), validateGainBounds(base, gains), objective.validate()});
        if (!e.empty()) throw std::invalid_argument(e);
        return withBox(params, gains);
      }()) {
  problem_ = std::make_unique<TuningProblem>(base, reference, gains, objective, problem_threads);
}

TuningSession::TuningSession(std::unique_ptr<const GainObjective> problem, PsoParams params)
    : problem_(std::move(problem)), search_(withBox(std::move(params), problem_->gains())) {}

int TuningSession::step(const TuningBatch& batch) {
  const int it = search_.iteration();
  const std::size_t n = search_.positions().size();
  costs_.assign(n, TuningCost());
  batch(search_.positions(), search_.bounds(), costs_);
  totals_.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    totals_[j] = costs_[j].total;
    if (costs_[j].bounded) ++cut_;
    simulated_ns_ += std::llround(costs_[j].simulated * 1e9);
  }
  search_.tell(totals_);
  return it;
}

std::string TuningSession::toText() const {
  return "tuning_tally " + std::to_string(cut_) + " " + std::to_string(simulated_ns_) + "\n" + search_.toText();
}

void TuningSession::restore(const std::string& text) {
  long long cut = 0, sim = 0;
  int used = 0;
  if (std::sscanf(text.c_str(), "tuning_tally %lld %lld\n%n", &cut, &sim, &used) != 2 || used <= 0 || cut < 0 ||
      sim < 0)
    throw std::invalid_argument("tuning state: the first line is not 'tuning_tally CUT SIMULATED_NS'");
  search_ = PsoSearch::fromText(search_.params(), text.substr(static_cast<std::size_t>(used)));
  cut_ = static_cast<long>(cut);
  simulated_ns_ = sim;
}

TuningResult TuningSession::result() const {
  if (!search_.finished()) throw std::logic_error("TuningSession::result: the search has not finished");
  TuningResult out;
  out.pso = search_.result();
  out.evaluations_cut = cut_;
  out.simulated_s = simulatedSeconds();
  out.best_gains = out.pso.best_position;
  out.best = problem_->evaluate(out.best_gains, 0);
  out.initial_best_cost = out.pso.best_cost_per_iteration.empty() ? INF : out.pso.best_cost_per_iteration.front();
  return out;
}

TuningResult tuneGains(const Scenario& base, const ReferenceSource& reference, const std::vector<GainBounds>& gains,
                       const TuningObjective& objective, PsoParams params, const PsoProgressCallback& progress) {
  const int threads = psoThreads(params);
  TuningSession session(base, reference, gains, objective, params, threads);
  const auto t0 = std::chrono::steady_clock::now();
  // Bounded: a particle's run stops once it cannot beat its personal best (same search, less work).
  const TuningBatch batch = threadedTuningBatch(session.problem(), session.params());
  const int iterations = session.params().iterations;
  while (!session.finished()) {
    const int it = session.step(batch);
    if (progress) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double eta = elapsed / static_cast<double>(it + 1) * static_cast<double>(iterations - it);
      progress(
          PsoProgress{it, iterations, session.search().bestCost(), &session.search().bestPosition(), elapsed, eta});
    }
  }
  TuningResult out = session.result();
  out.threads = threads;
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace core
}  // namespace sowing_robot
