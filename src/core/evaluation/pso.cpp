#include "sowing_robot/core/evaluation/pso.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <limits>
#include <mutex>
#include <random>
#include <stdexcept>
#include <thread>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

/// Uniform in [0, 1) from the top 53 bits; unlike std::uniform_real_distribution this is the same on
/// every standard library, and it can never return 1.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

/// Runs jobs 0..n-1 over `threads` threads: the caller is thread 0, threads 1..threads-1 are created once
/// and live as long as the pool. Jobs are handed out through an atomic index; run() returns once every
/// job has finished. The first exception thrown by a job is kept and rethrown by run() on the caller.
class EvaluationPool {
 public:
  using Job = std::function<void(int job, int thread_index)>;

  EvaluationPool(int threads, Job job) : job_(std::move(job)) {
    workers_.reserve(static_cast<std::size_t>(threads - 1));
    for (int t = 1; t < threads; ++t) workers_.emplace_back([this, t] { workerLoop(t); });
  }

  ~EvaluationPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    start_cv_.notify_all();
    for (auto& w : workers_) w.join();
  }

  EvaluationPool(const EvaluationPool&) = delete;
  EvaluationPool& operator=(const EvaluationPool&) = delete;

  void run(int jobs) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      jobs_ = jobs;
      next_.store(0);
      failed_.store(false);
      finished_workers_ = 0;
      ++generation_;
    }
    start_cv_.notify_all();
    work(0);
    std::unique_lock<std::mutex> lock(mutex_);
    done_cv_.wait(lock, [this] { return finished_workers_ == workers_.size(); });
    if (error_) {
      std::exception_ptr e = error_;
      error_ = nullptr;
      std::rethrow_exception(e);
    }
  }

 private:
  void work(int thread_index) {
    for (;;) {
      const int j = next_.fetch_add(1);
      if (j >= jobs_ || failed_.load()) return;
      try {
        job_(j, thread_index);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!error_) error_ = std::current_exception();
        failed_.store(true);
      }
    }
  }

  void workerLoop(int thread_index) {
    std::uint64_t seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        start_cv_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
      }
      work(thread_index);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++finished_workers_;
      }
      done_cv_.notify_one();
    }
  }

  Job job_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_cv_, done_cv_;
  std::uint64_t generation_ = 0;  ///< bumped by run(); guarded by mutex_
  std::size_t finished_workers_ = 0;
  bool stop_ = false;
  int jobs_ = 0;  ///< written under mutex_ before the generation bump, read-only while jobs run
  std::atomic<int> next_{0};
  std::atomic<bool> failed_{false};
  std::exception_ptr error_;
};

}  // namespace

double psoInertia(int i, int i_max, double w_max, double w_min) {
  if (i_max <= 0) return w_max;
  const double t = static_cast<double>(i) / static_cast<double>(i_max);
  return (1.0 - t) * w_max + t * w_min;
}

std::string PsoParams::validate() const {
  std::string e = firstError(
      {particles >= 1 ? "" : "particles = " + std::to_string(particles) + " must be >= 1",
       iterations >= 0 ? "" : "iterations = " + std::to_string(iterations) + " must be >= 0",
       checkNonNegative("w_min", w_min), checkRange("w_max", w_max, w_min, INF, "(must be >= w_min)"),
       checkNonNegative("c1", c1), checkNonNegative("c2", c2),
       checkNonNegative("max_velocity_fraction", max_velocity_fraction),
       threads >= 0 ? "" : "threads = " + std::to_string(threads) + " must be >= 0 (0 = hardware concurrency)",
       !lower.empty() ? "" : "lower/upper bounds are empty (need at least one dimension)",
       lower.size() == upper.size()
           ? ""
           : "lower has " + std::to_string(lower.size()) + " entries but upper has " + std::to_string(upper.size())});
  if (!e.empty()) return e;
  for (std::size_t d = 0; d < lower.size(); ++d) {
    const std::string i = "[" + std::to_string(d) + "]";
    e = checkOrdered("lower" + i, lower[d], "upper" + i, upper[d]);
    if (!e.empty()) return e;
    if (!std::isfinite(upper[d] - lower[d])) return "upper" + i + " - lower" + i + " overflows (range too large)";
  }
  return "";
}

PsoResult psoMinimize(const PsoParams& p, const PsoFitness& fitness, const PsoProgressCallback& progress) {
  if (!fitness) throw std::invalid_argument("psoMinimize: fitness is empty");
  return psoMinimize(
      p, PsoBoundedFitness([&fitness](const std::vector<double>& x, int t, double) { return fitness(x, t); }),
      progress);
}

PsoResult psoMinimize(const PsoParams& p, const PsoBoundedFitness& fitness, const PsoProgressCallback& progress) {
  const std::string error = p.validate();
  if (!error.empty()) throw std::invalid_argument("PsoParams: " + error);
  if (!fitness) throw std::invalid_argument("psoMinimize: fitness is empty");

  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = static_cast<std::size_t>(p.particles);
  const std::size_t dims = p.dimensions();

  int threads = p.threads > 0 ? p.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::clamp(threads, 1, p.particles);

  std::vector<double> range(dims), v_max(dims);
  for (std::size_t d = 0; d < dims; ++d) {
    range[d] = p.upper[d] - p.lower[d];
    v_max[d] = p.max_velocity_fraction > 0.0 ? p.max_velocity_fraction * range[d] : INF;
  }

  // One RNG stream per particle, so the random numbers a particle sees depend only on (seed, index).
  std::vector<std::mt19937_64> rng;
  rng.reserve(n);
  for (std::size_t j = 0; j < n; ++j) rng.emplace_back(splitmix64(splitmix64(p.seed) ^ splitmix64(0xA5A5A5A5ULL + j)));

  // Uniform random start inside the box, zero velocity.
  std::vector<std::vector<double>> x(n, std::vector<double>(dims)), v(n, std::vector<double>(dims, 0.0));
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t d = 0; d < dims; ++d) x[j][d] = std::min(p.lower[d] + uniform01(rng[j]) * range[d], p.upper[d]);

  std::vector<std::vector<double>> pbest = x;
  std::vector<double> pbest_cost(n, INF), cost(n, INF);
  std::vector<double> gbest = x[0];
  double gbest_cost = INF;

  PsoResult result;
  result.best_cost_per_iteration.reserve(static_cast<std::size_t>(p.iterations) + 1);
  result.evaluations = 0;

  EvaluationPool pool(threads, [&](int j, int thread_index) {
    // pbest_cost changes only between evaluation rounds, on the caller thread.
    const double c = fitness(x[static_cast<std::size_t>(j)], thread_index, pbest_cost[static_cast<std::size_t>(j)]);
    cost[static_cast<std::size_t>(j)] = std::isfinite(c) ? c : INF;
  });

  for (int it = 0; it <= p.iterations; ++it) {
    if (it > 0) {
      // Velocity (eq 4.27), position (eq 4.28) and box (eq 4.29) for every particle, serially on the
      // caller thread with each particle's own stream: r1 then r2, per dimension in order.
      const double w = psoInertia(it, p.iterations, p.w_max, p.w_min);
      for (std::size_t j = 0; j < n; ++j) {
        for (std::size_t d = 0; d < dims; ++d) {
          const double r1 = uniform01(rng[j]);
          const double r2 = uniform01(rng[j]);
          double vd = w * v[j][d] + p.c1 * r1 * (pbest[j][d] - x[j][d]) + p.c2 * r2 * (gbest[d] - x[j][d]);
          vd = std::clamp(vd, -v_max[d], v_max[d]);
          double xd = x[j][d] + vd;
          // A particle that hits a bound stays on it with that velocity component zeroed (a common
          // choice), so the inertia term does not keep pushing it out of the box on later iterations.
          if (xd < p.lower[d]) {
            xd = p.lower[d];
            vd = 0.0;
          } else if (xd > p.upper[d]) {
            xd = p.upper[d];
            vd = 0.0;
          }
          x[j][d] = xd;
          v[j][d] = vd;
        }
      }
    }

    pool.run(p.particles);
    result.evaluations += p.particles;

    // Personal and global bests (eqs 4.30, 4.31), serially in particle order; strict '<' so ties keep
    // the older best and +inf never becomes one.
    for (std::size_t j = 0; j < n; ++j) {
      if (cost[j] < pbest_cost[j]) {
        pbest_cost[j] = cost[j];
        pbest[j] = x[j];  // same size: copies without allocating
        if (cost[j] < gbest_cost) {
          gbest_cost = cost[j];
          gbest = x[j];
        }
      }
    }
    result.best_cost_per_iteration.push_back(gbest_cost);

    if (progress) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double eta = elapsed / static_cast<double>(it + 1) * static_cast<double>(p.iterations - it);
      progress(PsoProgress{it, p.iterations, gbest_cost, &gbest, elapsed, eta});
    }
  }

  result.best_position = gbest;
  result.best_cost = gbest_cost;
  return result;
}

}  // namespace core
}  // namespace sowing_robot
