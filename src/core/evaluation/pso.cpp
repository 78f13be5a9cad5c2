#include "sowing_robot/core/evaluation/pso.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>
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

PsoSearch::PsoSearch(const PsoParams& p) : p_(p), gbest_cost_(INF) {
  const std::string error = p.validate();
  if (!error.empty()) throw std::invalid_argument("PsoParams: " + error);
  const std::size_t n = static_cast<std::size_t>(p.particles);
  const std::size_t dims = p.dimensions();
  range_.resize(dims);
  v_max_.resize(dims);
  for (std::size_t d = 0; d < dims; ++d) {
    range_[d] = p.upper[d] - p.lower[d];
    v_max_[d] = p.max_velocity_fraction > 0.0 ? p.max_velocity_fraction * range_[d] : INF;
  }
  // One RNG stream per particle, so the random numbers a particle sees depend only on (seed, index).
  rng_.reserve(n);
  for (std::size_t j = 0; j < n; ++j) rng_.emplace_back(splitmix64(splitmix64(p.seed) ^ splitmix64(0xA5A5A5A5ULL + j)));
  // Uniform random start inside the box, zero velocity.
  x_.assign(n, std::vector<double>(dims));
  v_.assign(n, std::vector<double>(dims, 0.0));
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t d = 0; d < dims; ++d) x_[j][d] = std::min(p.lower[d] + uniform01(rng_[j]) * range_[d], p.upper[d]);
  pbest_ = x_;
  pbest_cost_.assign(n, INF);
  gbest_ = x_[0];
  history_.reserve(static_cast<std::size_t>(p.iterations) + 1);
}

void PsoSearch::move() {
  // Velocity (eq 4.27), position (eq 4.28) and box (eq 4.29) for every particle, serially with each
  // particle's own stream: r1 then r2, per dimension in order.
  const double w = psoInertia(iteration_, p_.iterations, p_.w_max, p_.w_min);
  for (std::size_t j = 0; j < x_.size(); ++j) {
    for (std::size_t d = 0; d < range_.size(); ++d) {
      const double r1 = uniform01(rng_[j]);
      const double r2 = uniform01(rng_[j]);
      double vd = w * v_[j][d] + p_.c1 * r1 * (pbest_[j][d] - x_[j][d]) + p_.c2 * r2 * (gbest_[d] - x_[j][d]);
      vd = std::clamp(vd, -v_max_[d], v_max_[d]);
      double xd = x_[j][d] + vd;
      // A particle that hits a bound stays on it with that velocity component zeroed (a common
      // choice), so the inertia term does not keep pushing it out of the box on later iterations.
      if (xd < p_.lower[d]) {
        xd = p_.lower[d];
        vd = 0.0;
      } else if (xd > p_.upper[d]) {
        xd = p_.upper[d];
        vd = 0.0;
      }
      x_[j][d] = xd;
      v_[j][d] = vd;
    }
  }
}

void PsoSearch::tell(const std::vector<double>& costs) {
  if (finished()) throw std::logic_error("PsoSearch::tell: the search has finished");
  if (costs.size() != x_.size())
    throw std::logic_error("PsoSearch::tell: " + std::to_string(costs.size()) + " costs for " +
                           std::to_string(x_.size()) + " particles");
  evaluations_ += static_cast<long>(x_.size());
  // Personal and global bests (eqs 4.30, 4.31), serially in particle order; strict '<' so ties keep
  // the older best and +inf never becomes one.
  for (std::size_t j = 0; j < x_.size(); ++j) {
    const double c = std::isfinite(costs[j]) ? costs[j] : INF;
    if (c < pbest_cost_[j]) {
      pbest_cost_[j] = c;
      pbest_[j] = x_[j];  // same size: copies without allocating
      if (c < gbest_cost_) {
        gbest_cost_ = c;
        gbest_ = x_[j];
      }
    }
  }
  history_.push_back(gbest_cost_);
  ++iteration_;
  if (!finished()) move();
}

PsoResult PsoSearch::result() const {
  PsoResult r;
  r.best_position = gbest_;
  r.best_cost = gbest_cost_;
  r.best_cost_per_iteration = history_;
  r.evaluations = evaluations_;
  return r;
}

namespace {

void putHex(std::string& out, double v) {
  char b[40];
  std::snprintf(b, sizeof b, " %a", v);
  out += b;
}

void putRow(std::string& out, const char* key, const std::vector<double>& row) {
  out += key;
  for (double v : row) putHex(out, v);
  out += '\n';
}

/// Reads the tokens of one text state, each failure one line naming what was expected.
class StateReader {
 public:
  explicit StateReader(const std::string& text) : in_(text) {}
  void expect(const std::string& word) {
    std::string w;
    if (!(in_ >> w) || w != word) fail("expected '" + word + "', found '" + w + "'");
  }
  double number() {
    std::string w;
    if (!(in_ >> w)) fail("ends early");
    char* end = nullptr;
    const double v = std::strtod(w.c_str(), &end);
    if (w.empty() || *end != '\0' || std::isnan(v)) fail("'" + w + "' is no number");
    return v;
  }
  long long integer() {
    std::string w;
    if (!(in_ >> w)) fail("ends early");
    char* end = nullptr;
    const long long v = std::strtoll(w.c_str(), &end, 10);
    if (w.empty() || *end != '\0') fail("'" + w + "' is no integer");
    return v;
  }
  void row(const char* key, std::vector<double>& out) {
    expect(key);
    for (double& v : out) v = number();
  }
  void generator(std::mt19937_64& g) {
    expect("rng");
    if (!(in_ >> g)) fail("a particle's generator state is damaged");
  }
  void end() {
    std::string w;
    if (in_ >> w) fail("unexpected '" + w + "' after the end");
  }
  [[noreturn]] static void fail(const std::string& what) { throw std::invalid_argument("PSO state: " + what); }

 private:
  std::istringstream in_;
};

/// The parameters a state belongs to, as one line (exact: hex floats).
std::string paramsLine(const PsoParams& p) {
  std::string s = "params " + std::to_string(p.particles) + " " + std::to_string(p.dimensions()) + " " +
                  std::to_string(p.iterations) + " " + std::to_string(p.seed);
  for (double v : {p.w_max, p.w_min, p.c1, p.c2, p.max_velocity_fraction}) putHex(s, v);
  for (double v : p.lower) putHex(s, v);
  for (double v : p.upper) putHex(s, v);
  return s;
}

}  // namespace

std::string PsoSearch::toText() const {
  std::string out = "pso_state 1\n" + paramsLine(p_) + "\n";
  out += "iteration " + std::to_string(iteration_) + "\nevaluations " + std::to_string(evaluations_) + "\n";
  out += "gbest_cost";
  putHex(out, gbest_cost_);
  out += "\n";
  putRow(out, "gbest", gbest_);
  out += "history " + std::to_string(history_.size());
  for (double v : history_) putHex(out, v);
  out += "\n";
  for (std::size_t j = 0; j < x_.size(); ++j) {
    out += "particle " + std::to_string(j) + "\n";
    putRow(out, "x", x_[j]);
    putRow(out, "v", v_[j]);
    putRow(out, "pbest", pbest_[j]);
    out += "pbest_cost";
    putHex(out, pbest_cost_[j]);
    out += "\n";
    std::ostringstream g;
    g << rng_[j];
    out += "rng " + g.str() + "\n";
  }
  return out;
}

PsoSearch PsoSearch::fromText(const PsoParams& params, const std::string& text) {
  PsoSearch s(params);
  StateReader r(text);
  r.expect("pso_state");
  if (r.integer() != 1) StateReader::fail("unknown version (this build reads version 1)");
  // The parameters line must be this search's, word for word.
  const std::string want = paramsLine(params);
  const std::size_t at = text.find('\n');
  const std::size_t end = at == std::string::npos ? at : text.find('\n', at + 1);
  if (at == std::string::npos || end == std::string::npos || text.compare(at + 1, end - at - 1, want) != 0)
    StateReader::fail(
        "it belongs to other PSO parameters (particles, dimensions, iterations, seed, coefficients "
        "or bounds differ)");
  r.expect("params");
  for (std::size_t k = 0; k < 4 + 5 + 2 * params.dimensions(); ++k) r.number();
  r.expect("iteration");
  const long long it = r.integer();
  if (it < 0 || it > params.iterations + 1) StateReader::fail("iteration " + std::to_string(it) + " out of range");
  s.iteration_ = static_cast<int>(it);
  r.expect("evaluations");
  s.evaluations_ = static_cast<long>(r.integer());
  r.expect("gbest_cost");
  s.gbest_cost_ = r.number();
  r.row("gbest", s.gbest_);
  r.expect("history");
  if (r.integer() != it) StateReader::fail("history length differs from the iteration");
  s.history_.assign(static_cast<std::size_t>(it), 0.0);
  for (double& v : s.history_) v = r.number();
  for (std::size_t j = 0; j < s.x_.size(); ++j) {
    r.expect("particle");
    if (r.integer() != static_cast<long long>(j)) StateReader::fail("particles out of order");
    r.row("x", s.x_[j]);
    r.row("v", s.v_[j]);
    r.row("pbest", s.pbest_[j]);
    r.expect("pbest_cost");
    s.pbest_cost_[j] = r.number();
    r.generator(s.rng_[j]);
  }
  r.end();
  return s;
}

std::function<void(int)> psoThreadPool(int threads, PsoJob job) {
  auto pool = std::make_shared<EvaluationPool>(std::max(threads, 1), std::move(job));
  return [pool](int jobs) { pool->run(jobs); };
}

PsoBatch psoThreadedBatch(const PsoParams& p, const PsoBoundedFitness& fitness) {
  if (!fitness) throw std::invalid_argument("psoThreadedBatch: fitness is empty");
  int threads = p.threads > 0 ? p.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::clamp(threads, 1, std::max(p.particles, 1));
  struct Batch {  // the batch being evaluated, set before each run
    const std::vector<std::vector<double>>* x = nullptr;
    const std::vector<double>* bounds = nullptr;
    std::vector<double>* costs = nullptr;
  };
  auto batch = std::make_shared<Batch>();
  auto run = psoThreadPool(threads, [batch, fitness](int j, int thread_index) {
    const auto k = static_cast<std::size_t>(j);
    (*batch->costs)[k] = fitness((*batch->x)[k], thread_index, (*batch->bounds)[k]);
  });
  return [batch, run](const std::vector<std::vector<double>>& x, const std::vector<double>& bounds,
                      std::vector<double>& costs) {
    batch->x = &x;
    batch->bounds = &bounds;
    batch->costs = &costs;
    run(static_cast<int>(x.size()));
  };
}

PsoResult psoMinimize(const PsoParams& p, const PsoBoundedFitness& fitness, const PsoProgressCallback& progress) {
  PsoSearch search(p);
  if (!fitness) throw std::invalid_argument("psoMinimize: fitness is empty");
  const auto t0 = std::chrono::steady_clock::now();
  const PsoBatch batch = psoThreadedBatch(p, fitness);
  std::vector<double> cost(static_cast<std::size_t>(p.particles), INF);
  while (!search.finished()) {
    const int it = search.iteration();
    batch(search.positions(), search.bounds(), cost);
    search.tell(cost);
    if (progress) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double eta = elapsed / static_cast<double>(it + 1) * static_cast<double>(p.iterations - it);
      progress(PsoProgress{it, p.iterations, search.bestCost(), &search.bestPosition(), elapsed, eta});
    }
  }
  return search.result();
}

}  // namespace core
}  // namespace sowing_robot
