// Offline gain tuning (thesis eqs 4.26-4.31, Table 5.4): the PSO of pso.h searching a box of controller
// gains, each particle scored by one in-process closed-loop run (runner.h). ROS-free, so the pso_tuner
// node and the pso_tuning_bench program share exactly the same objective.
#pragma once

#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "sowing_robot/core/pso.h"
#include "sowing_robot/core/reference.h"
#include "sowing_robot/core/runner.h"

namespace sowing_robot {
namespace core {

/// The tracking index summed over x, y and theta (definitions in metrics.h).
enum class CostType { ITAE, ISE, IAE, ITSE };
/// "itae" | "ise" | "iae" | "itse" -> type; false if unknown.
bool parseCostType(const std::string& name, CostType& out);
const char* costTypeName(CostType type);

/// The gains the tuner may search, in their node's parameter names:
/// kx, ky, ktheta (kinematic_controller) and k1, k2, eta1, eta2, beta_v, beta_omega, rate_m, rate_i
/// (torque_controller).
const std::vector<std::string>& tunableGainNames();
/// "kinematic_controller" or "torque_controller" for a tunable gain, "" for anything else.
std::string gainNode(const std::string& name);
/// Set / read a tunable gain in the scenario; false / NaN for an unknown name.
bool setGain(Scenario& sc, const std::string& name, double value);
double getGain(const Scenario& sc, const std::string& name);

/// One dimension of the search box [same unit as the gain].
struct GainBounds {
  std::string name;
  double lower = 0.0, upper = 0.0;
};

/// The default search space: Kanayama kx, ky, ktheta in [0.1, 10]; K1, K2 in [0.1, 1000] (Table 5.4);
/// eta1, eta2 in [0.1, 10] N·m.
std::vector<GainBounds> defaultGainBounds();

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

/// Scores gain vectors (in the order of `gains`) on a base scenario. evaluate() may be called from
/// several threads at once as long as each uses its own thread_index < threads (as psoMinimize does):
/// each index has its own clone of the reference. No allocation per control step.
class TuningProblem {
 public:
  TuningProblem(const Scenario& base, const ReferenceSource& reference, std::vector<GainBounds> gains,
                const TuningObjective& objective, int threads);

  /// The base scenario with the given gains applied.
  Scenario scenarioFor(const std::vector<double>& position) const;
  /// A diverged run or any non-finite term gives total = +inf. With a finite `bound` the run stops as
  /// soon as the cost so far (every term only grows with time) has reached it; total is then that
  /// partial cost, >= bound, and `bounded` is set (what psoMinimize's bounded fitness may do).
  TuningCost evaluate(const std::vector<double>& position, int thread_index,
                      double bound = std::numeric_limits<double>::infinity()) const;

  const std::vector<GainBounds>& gains() const { return gains_; }
  const Scenario& base() const { return base_; }
  const TuningObjective& objective() const { return objective_; }

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

/// Resolved number of evaluation threads psoMinimize will use for these parameters.
int psoThreads(const PsoParams& params);

/// Validate, then minimise the objective over the box with psoMinimize (params.lower/upper are filled
/// from `gains`). Throws std::invalid_argument with a one-line message on bad input.
TuningResult tuneGains(const Scenario& base, const ReferenceSource& reference, const std::vector<GainBounds>& gains,
                       const TuningObjective& objective, PsoParams params, const PsoProgressCallback& progress = {});

}  // namespace core
}  // namespace sowing_robot
