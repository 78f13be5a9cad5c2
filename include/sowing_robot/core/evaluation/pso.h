// Offline Particle Swarm Optimisation (thesis eqs 4.26-4.31, Table 5.4): a box-bounded minimiser with a
// linearly decreasing inertia weight. Fitness evaluations of one iteration run in parallel; the result
// depends only on the parameters (seed included), never on the number of threads.
//
// Two ways in: psoMinimize (threads, one call) and PsoSearch (ask/tell: the caller evaluates each
// iteration's positions however it likes, e.g. on MPI ranks, and tells the costs back). psoMinimize is
// PsoSearch driven by a thread pool, so both give the same numbers bit for bit. A PsoSearch between two
// iterations can be written as text and read back exactly (checkpoints).
#pragma once

#include <cstdint>
#include <functional>
#include <random>
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

/// Evaluates a whole iteration: costs[j] = the (bounded) cost of positions[j] with bound bounds[j], for
/// every j, in any order and with any parallelism. costs has positions.size() entries on entry.
using PsoBatch = std::function<void(const std::vector<std::vector<double>>& positions,
                                    const std::vector<double>& bounds, std::vector<double>& costs)>;

/// The PSO as ask/tell: positions() are the swarm of iteration(), bounds() each particle's personal best
/// cost (the bound a PsoBoundedFitness may stop at); tell() takes their costs, updates the personal and
/// global bests (eqs 4.30, 4.31) and, unless that was the last iteration, moves the swarm (eqs 4.26-4.29)
/// to the next one. Driving it with the same costs gives the same search as psoMinimize, bit for bit.
class PsoSearch {
 public:
  /// The initial swarm (iteration 0). Throws std::invalid_argument with params.validate()'s message.
  explicit PsoSearch(const PsoParams& params);

  const PsoParams& params() const { return p_; }
  /// The iteration whose positions await their costs (0..iterations); iterations + 1 once finished.
  int iteration() const { return iteration_; }
  bool finished() const { return iteration_ > p_.iterations; }
  const std::vector<std::vector<double>>& positions() const { return x_; }
  const std::vector<double>& bounds() const { return pbest_cost_; }
  /// Costs of positions() (non-finite counts as +inf). Throws std::logic_error when finished or the size
  /// is wrong.
  void tell(const std::vector<double>& costs);

  double bestCost() const { return gbest_cost_; }
  const std::vector<double>& bestPosition() const { return gbest_; }
  /// PsoResult of what has been told so far (the final result once finished()).
  PsoResult result() const;

  /// Every number of the state as text: hex floats (exact), the particles' generators in the standard's
  /// text form (exact). fromText() reads it back for the same parameters; a text of other parameters
  /// (particles, dimensions, iterations, seed, bounds, coefficients) or a damaged one throws
  /// std::invalid_argument with one line.
  std::string toText() const;
  static PsoSearch fromText(const PsoParams& params, const std::string& text);

 private:
  void move();

  PsoParams p_;
  int iteration_ = 0;
  std::vector<std::mt19937_64> rng_;
  std::vector<std::vector<double>> x_, v_, pbest_;
  std::vector<double> pbest_cost_, gbest_, history_, range_, v_max_;
  double gbest_cost_;
  long evaluations_ = 0;
};

/// A pool of `threads` threads (the caller's included, >= 1) that runs job(j, thread_index) for j in
/// 0..jobs-1 on each call, handing the next j to whichever thread is free; returns when all are done and
/// rethrows the first exception a job threw. What psoThreadedBatch and the tuner's batch run on.
using PsoJob = std::function<void(int job, int thread_index)>;
std::function<void(int jobs)> psoThreadPool(int threads, PsoJob job);

/// A PsoBatch over `threads` threads (the caller's included; 0 = hardware concurrency, never more than
/// the particles) calling fitness(position, thread_index, bound): psoMinimize's own evaluation. The
/// first exception thrown by fitness is rethrown on the caller once the threads have stopped.
PsoBatch psoThreadedBatch(const PsoParams& params, const PsoBoundedFitness& fitness);

/// Minimise `fitness` over the box [lower, upper]. Throws std::invalid_argument with params.validate()'s
/// message if the parameters are bad. An exception thrown by fitness is rethrown on the caller thread
/// (after the worker threads have stopped); so is one thrown by progress.
PsoResult psoMinimize(const PsoParams& params, const PsoFitness& fitness, const PsoProgressCallback& progress = {});
PsoResult psoMinimize(const PsoParams& params, const PsoBoundedFitness& fitness,
                      const PsoProgressCallback& progress = {});

}  // namespace core
}  // namespace sowing_robot
