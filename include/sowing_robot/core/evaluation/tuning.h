// Offline gain tuning (thesis eqs 4.26-4.31, Table 5.4): the PSO of pso.h searching a box of controller
// gains, each particle scored by one in-process closed-loop run (runner.h). ROS-free, so the pso_tuner
// node and the pso_tuning_bench program share exactly the same objective.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/evaluation/pso.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {
namespace core {

/// The tracking index summed over x, y and theta (definitions in metrics.h).
enum class CostType { ITAE, ISE, IAE, ITSE };
/// "itae" | "ise" | "iae" | "itse" -> type; false if unknown.
bool parseCostType(const std::string& name, CostType& out);
const char* costTypeName(CostType type);

/// The gains the tuner may search for the scenario's controller pair (Scenario::outer, inner), outer's
/// then inner's, each in its table's order: the entries marked `tunable` in kanayamaTable() /
/// purePursuitTable() (outer) and slidingModeTable() / wheelPidTable() (inner). Two marks only apply
/// where they act: rate_m, rate_i only for an adaptive sliding-mode inner (ATSMC), RPP's
/// regulated_linear_scaling_min_radius only for rpp. Names are the tables' keys (unique over all four).
std::vector<std::string> tunableGainNames(const Scenario& sc);
/// The same for the default pair kanayama+atsmc: kx, ky, ktheta, beta_v, ..., rate_m, rate_i.
const std::vector<std::string>& tunableGainNames();
/// The node whose parameters hold this gain of the scenario's pair ("kinematic_controller" or
/// "torque_controller"), "" if the pair has no such tunable gain.
std::string gainNode(const Scenario& sc, const std::string& name);
/// The gain's key under its node, as the nodes and the gains YAML nest it: "kx", "k1" (Kanayama and the
/// sliding-mode table at the node's top level), "pure_pursuit/lookahead_dist", "pid/kp".
std::string gainKey(const Scenario& sc, const std::string& name);
/// Set / read a tunable gain of the scenario's pair; false / NaN for a name the pair does not tune.
bool setGain(Scenario& sc, const std::string& name, double value);
double getGain(const Scenario& sc, const std::string& name);

/// One parameter of a controller by its node and key as in a gains YAML or the node's namespace
/// (gainKey's nesting; any table entry, tunable or not: "torque_controller", "adaptation", "eq_4_22").
/// Applies to the scenario's tables whatever the pair. "" or one line naming the bad key or value.
std::string setControllerParam(Scenario& sc, const std::string& node, const std::string& key, const ParamValue& value);

/// One dimension of the search box [same unit as the gain].
struct GainBounds {
  std::string name;
  double lower = 0.0, upper = 0.0;
};

/// The search bounds of every tunable gain, one list beside the tables (tuning.cpp): Kanayama kx, ky,
/// ktheta [0.1, 10]; beta [0.1, 2], K1, K2 [0.1, 1000] (Table 5.4); eta [0.1, 10] N·m; rates [0, 10];
/// pure pursuit lookahead [0.3, 0.9] m (nav2's min/max), k_along [0, 10] 1/s, RPP min radius [0.1, 3] m;
/// PID kp [0, 50], ki [0, 500], kd [0, 0.5], feedforward [0, 2]. NaN bounds for an unknown name.
GainBounds gainSearchBounds(const std::string& name);
/// The whole search space of the scenario's pair: every tunableGainNames(sc) with gainSearchBounds.
std::vector<GainBounds> defaultGainBounds(const Scenario& sc);
/// The seven gains results/tuned_gains.yaml searched (kanayama+atsmc without beta and the rates): kx,
/// ky, ktheta [0.1, 10]; K1, K2 [0.1, 1000] (Table 5.4); eta1, eta2 [0.1, 10] N·m.
std::vector<GainBounds> defaultGainBounds();

/// The gains YAML body: every tunable gain of the tuned scenario's pair under its node (gainKey's
/// nesting: pure_pursuit:, pid: sub-maps), the tuned ones commented with their bounds, the others
/// "base value (not tuned)"; for an adaptive sliding-mode inner also torque_controller/adaptation (the
/// reading the rates were tuned for). rosparam-loadable; sim.launch gains:=FILE.
std::string gainsYaml(const Scenario& tuned, const std::vector<GainBounds>& searched);
/// Shortest round-trip decimal form of v that YAML 1.1 (rosparam) reads as a float (always has a '.').
std::string yamlFloat(double v);

/// "" if the list is usable with this base scenario, else one line naming the first bad entry: empty
/// list, unknown or repeated name, non-finite bound, lower >= upper, or a bound the controller itself
/// would reject (checked by validating the scenario with every gain at its lower, then its upper bound).
std::string validateGainBounds(const Scenario& base, const std::vector<GainBounds>& gains);

struct TuningObjective {
  CostType cost = CostType::ITAE;
  /// Weight of the control effort  int_0^T (tau_R^2 + tau_L^2) dt  [N^2·m^2·s] (>= 0, 0 = off).
  double torque_weight = 0.0;
  /// Weight of the chattering  sum_k (|tau_R,k - tau_R,k-1| + |tau_L,k - tau_L,k-1|)  [N·m] (>= 0, 0 = off).
  double chattering_weight = 0.0;

  std::string validate() const;
};

/// One evaluation, split into its terms (unweighted effort and chattering).
struct TuningCost {
  double total = 0.0;     ///< tracking + torque_weight * effort + chattering_weight * chattering; +inf if bad
  double tracking = 0.0;  ///< the chosen index summed over x, y, theta
  double effort = 0.0;    ///< int (tau_R^2 + tau_L^2) dt
  double chattering = 0.0;
  bool diverged = false;
  bool bounded = false;    ///< the run was stopped once total reached the bound: total is a lower bound
  double simulated = 0.0;  ///< simulated time actually run [s]
};

/// What the tuner searches: gain vectors (in the order of gains()) and their score. Two kinds: one run on
/// one scenario (TuningProblem, below) and a training set of runs (RobustTuningProblem, robust_tuning.h).
/// evaluate() may be called from several threads at once as long as each uses its own thread_index <
/// threads().
class GainObjective {
 public:
  virtual ~GainObjective() = default;
  virtual const std::vector<GainBounds>& gains() const = 0;
  /// The controller settings the gains stand for (what gainsYaml writes) with the given gains applied.
  virtual Scenario scenarioFor(const std::vector<double>& position) const = 0;
  /// The cost (+inf if bad); with a finite `bound` the evaluation may stop once the cost has reached it
  /// (total >= bound, `bounded` set: what psoMinimize's bounded fitness allows).
  virtual TuningCost evaluate(const std::vector<double>& position, int thread_index,
                              double bound = std::numeric_limits<double>::infinity()) const = 0;
  /// How many thread indices evaluate() accepts (0..threads()-1).
  virtual int threads() const = 0;
};

/// Scores gain vectors (in the order of `gains`) on a base scenario. evaluate() may be called from
/// several threads at once as long as each uses its own thread_index < threads (as psoMinimize does):
/// each index has its own clone of the reference. No allocation per control step.
class TuningProblem : public GainObjective {
 public:
  TuningProblem(const Scenario& base, const ReferenceSource& reference, std::vector<GainBounds> gains,
                const TuningObjective& objective, int threads);

  /// The base scenario with the given gains applied.
  Scenario scenarioFor(const std::vector<double>& position) const override;
  /// A diverged run or any non-finite term gives total = +inf. With a finite `bound` the run stops as
  /// soon as the cost so far (every term only grows with time) has reached it; total is then that
  /// partial cost, >= bound, and `bounded` is set (what psoMinimize's bounded fitness may do).
  TuningCost evaluate(const std::vector<double>& position, int thread_index,
                      double bound = std::numeric_limits<double>::infinity()) const override;

  const std::vector<GainBounds>& gains() const override { return gains_; }
  const Scenario& base() const { return base_; }
  const TuningObjective& objective() const { return objective_; }
  /// How many thread indices evaluate() accepts (0..threads()-1).
  int threads() const override { return static_cast<int>(references_.size()); }

 private:
  Scenario base_;
  std::vector<GainBounds> gains_;
  TuningObjective objective_;
  std::vector<std::unique_ptr<ReferenceSource>> references_;

  /// The weighted total of the terms, added in one fixed order: the same formula for a partial and a
  /// whole run, so a partial total is never above the whole run's (floating-point sums of non-negative
  /// terms only grow).
  void total(const std::array<AxisMetrics, AXIS_COUNT>& metrics, double effort, double chattering, TuningCost& c) const;
};

struct TuningResult {
  PsoResult pso;
  std::vector<double> best_gains;  ///< same order as the bounds
  TuningCost best;                 ///< breakdown of the best cost (one more run)
  double initial_best_cost = 0.0;  ///< best of iteration 0 (the random initial swarm)
  int threads = 1;                 ///< evaluation threads actually used
  double wall_s = 0.0;
  long evaluations_cut = 0;  ///< evaluations stopped early by their particle's bound
  double simulated_s = 0.0;  ///< simulated time run over all evaluations [s]
};

/// Scores a whole iteration for the tuner: out[j] = the problem's evaluate(positions[j], ., bounds[j]) for
/// every j (any order, any parallelism; out has positions.size() entries on entry). The search uses
/// out[j].total; bounded and simulated feed the tallies. threadedTuningBatch is tuneGains' own; the MPI
/// farm (farm/tune_farm.h) sends the same evaluate() to other processes.
using TuningBatch = std::function<void(const std::vector<std::vector<double>>& positions,
                                       const std::vector<double>& bounds, std::vector<TuningCost>& out)>;
/// The batch on psoThreads(params) threads, at most problem.threads() (the pool of psoThreadedBatch over
/// problem.evaluate).
TuningBatch threadedTuningBatch(const GainObjective& problem, const PsoParams& params);

/// tuneGains in steps: the search of tuneGains (same problem, bounds, bound per particle) driven one
/// iteration at a time by any TuningBatch, so it can be checkpointed (toText / restore) and resumed, or
/// evaluated on other processes; whatever the batch, the same costs give the same gains bit for bit.
class TuningSession {
 public:
  /// Validates like tuneGains (std::invalid_argument, one line); params.lower/upper come from `gains`.
  /// problem_threads: how many thread indices the problem's evaluate() accepts.
  TuningSession(const Scenario& base, const ReferenceSource& reference, const std::vector<GainBounds>& gains,
                const TuningObjective& objective, PsoParams params, int problem_threads);
  /// The same search over any objective (e.g. a RobustTuningProblem); params.lower/upper come from its gains.
  TuningSession(std::unique_ptr<const GainObjective> problem, PsoParams params);

  const GainObjective& problem() const { return *problem_; }
  const PsoParams& params() const { return search_.params(); }
  const PsoSearch& search() const { return search_; }
  bool finished() const { return search_.finished(); }
  /// Evaluates the current iteration with `batch` and tells the search; returns the iteration done.
  int step(const TuningBatch& batch);
  long evaluationsCut() const { return cut_; }
  double simulatedSeconds() const { return 1e-9 * static_cast<double>(simulated_ns_); }

  /// The whole state between two iterations as text (the search's exact text and the tallies).
  std::string toText() const;
  /// Back to a state toText() wrote for the same parameters; std::invalid_argument (one line) otherwise.
  void restore(const std::string& text);
  /// What tuneGains returns, once finished (throws std::logic_error before): the best evaluated once more.
  /// wall_s and threads are left for the caller.
  TuningResult result() const;

 private:
  std::unique_ptr<const GainObjective> problem_;
  PsoSearch search_;
  long cut_ = 0;
  std::int64_t simulated_ns_ = 0;
  std::vector<TuningCost> costs_;
  std::vector<double> totals_;
};

/// Resolved number of evaluation threads psoMinimize will use for these parameters.
int psoThreads(const PsoParams& params);

/// Validate, then minimise the objective over the box with psoMinimize (params.lower/upper are filled
/// from `gains`). Throws std::invalid_argument with a one-line message on bad input.
TuningResult tuneGains(const Scenario& base, const ReferenceSource& reference, const std::vector<GainBounds>& gains,
                       const TuningObjective& objective, PsoParams params, const PsoProgressCallback& progress = {});

}  // namespace core
}  // namespace sowing_robot
