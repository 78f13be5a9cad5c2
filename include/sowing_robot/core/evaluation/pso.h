// Offline Particle Swarm Optimisation (thesis eqs 4.26-4.31, Table 5.4): a box-bounded minimiser with a
// linearly decreasing inertia weight. Fitness evaluations of one iteration run in parallel; the result
// depends only on the parameters (seed included), never on the number of threads.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace sowing_robot {
namespace core {

/// Inertia weight of iteration i (eq 4.26): w(i) = w_max - (w_max - w_min) / i_max * i, evaluated as
/// (1 - i/i_max) w_max + (i/i_max) w_min so that w(0) = w_max and w(i_max) = w_min exactly.
/// i_max <= 0 returns w_max.
double psoInertia(int i, int i_max, double w_max, double w_min);

struct PsoParams {
  int particles = 20;                  ///< swarm size (Table 5.4)
  int iterations = 30;                 ///< i_max: update+evaluate rounds after the initial evaluation (Table 5.4)
  double w_max = 0.9, w_min = 0.1;     ///< inertia weight at i = 0 and i = i_max [-] (eq 4.26)
  double c1 = 2.0, c2 = 2.0;           ///< cognitive and social acceleration coefficients [-] (eq 4.27)
  std::vector<double> lower, upper;    ///< per-dimension search box, lower < upper [unit of the dimension]
  double max_velocity_fraction = 0.0;  ///< |v_d| <= fraction * (upper_d - lower_d) [-]; 0 = no clamp
  std::uint64_t seed = 1;              ///< same seed -> bit-identical result, whatever `threads` is
  int threads = 0;                     ///< fitness evaluation threads (caller included); 0 = hardware_concurrency()

  /// "" if usable, else one line naming the first bad parameter, its value and the allowed range.
  std::string validate() const;
  /// Number of dimensions (size of the bounds).
  std::size_t dimensions() const { return lower.size(); }
};

/// Reported on the caller thread after each iteration, the initial evaluation (iteration 0) included.
struct PsoProgress {
  int iteration;                             ///< 0..iterations
  int iterations;                            ///< i_max
  double best_cost;                          ///< global best so far (+inf if nothing finite yet)
  const std::vector<double>* best_position;  ///< valid only during the callback
  double elapsed_s;                          ///< wall time since the start of psoMinimize [s]
  double eta_s;                              ///< estimated remaining wall time [s]
};

struct PsoResult {
  std::vector<double> best_position;            ///< global best (eq 4.31); particle 0's start if no cost was finite
  double best_cost;                             ///< its cost; +inf if no evaluation was finite
  std::vector<double> best_cost_per_iteration;  ///< global best after iteration 0..iterations (size i_max+1)
  long evaluations;                             ///< particles * (iterations + 1)
};

/// fitness(position, thread_index) -> cost to minimise. thread_index is in [0, min(threads, particles))
/// and no two concurrent calls share one, so callers can keep per-thread state (e.g. cloned references).
/// Calls may run concurrently on different threads. Non-finite costs count as +inf (never become a best).
using PsoFitness = std::function<double(const std::vector<double>&, int)>;
/// The same with the particle's personal best cost as `bound` (+inf before it has one). A cost that is
/// not below the bound changes nothing (no personal, hence no global, best), so the fitness may stop as
/// soon as it knows its cost is at least the bound and return any value >= bound: the search, its
/// random numbers and its result are exactly those of the exact fitness, only cheaper.
using PsoBoundedFitness = std::function<double(const std::vector<double>&, int, double bound)>;
using PsoProgressCallback = std::function<void(const PsoProgress&)>;

/// Minimise `fitness` over the box [lower, upper]. Throws std::invalid_argument with params.validate()'s
/// message if the parameters are bad. An exception thrown by fitness is rethrown on the caller thread
/// (after the worker threads have stopped); so is one thrown by progress.
PsoResult psoMinimize(const PsoParams& params, const PsoFitness& fitness, const PsoProgressCallback& progress = {});
PsoResult psoMinimize(const PsoParams& params, const PsoBoundedFitness& fitness,
                      const PsoProgressCallback& progress = {});

}  // namespace core
}  // namespace sowing_robot
