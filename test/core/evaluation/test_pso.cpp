// Offline PSO core: convergence on standard test functions, bounds, determinism across threads, the
// inertia schedule (eq 4.26), parameter validation and the bookkeeping of the result.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "sowing_robot/core/evaluation/pso.h"

using namespace sowing_robot::core;

namespace {

double sphere(const std::vector<double>& x) {
  double c = 0.0;
  for (double v : x) c += v * v;
  return c;
}

double rosenbrock2(const std::vector<double>& x) {
  const double a = 1.0 - x[0], b = x[1] - x[0] * x[0];
  return a * a + 100.0 * b * b;
}

double rastrigin(const std::vector<double>& x) {
  double c = 10.0 * static_cast<double>(x.size());
  for (double v : x) c += v * v - 10.0 * std::cos(2.0 * M_PI * v);
  return c;
}

PsoParams boxParams(std::size_t dims, double lo, double hi, int particles, int iterations, std::uint64_t seed = 1,
                    int threads = 1) {
  PsoParams p;
  p.lower.assign(dims, lo);
  p.upper.assign(dims, hi);
  p.particles = particles;
  p.iterations = iterations;
  p.seed = seed;
  p.threads = threads;
  return p;
}

/// Every position handed to the fitness, kept per thread_index so no locking is needed.
struct Recorder {
  explicit Recorder(int threads) : per_thread(static_cast<std::size_t>(threads)) {}
  std::vector<std::vector<std::vector<double>>> per_thread;
  std::vector<std::vector<double>> all() const {
    std::vector<std::vector<double>> out;
    for (const auto& t : per_thread) out.insert(out.end(), t.begin(), t.end());
    return out;
  }
};

}  // namespace

// ---- eq 4.26 -------------------------------------------------------------------------------------

TEST(PsoInertia, MatchesLinearScheduleAtStartMiddleAndEnd) {
  const int i_max = 30;
  const double w_max = 0.9, w_min = 0.1;
  auto formula = [&](int i) { return w_max - (w_max - w_min) / i_max * i; };
  EXPECT_NEAR(psoInertia(1, i_max, w_max, w_min), formula(1), 1e-15);
  EXPECT_NEAR(psoInertia(1, i_max, w_max, w_min), 0.9 - 0.8 / 30.0, 1e-15);
  EXPECT_NEAR(psoInertia(15, i_max, w_max, w_min), formula(15), 1e-15);
  EXPECT_NEAR(psoInertia(15, i_max, w_max, w_min), 0.5, 1e-15);
  EXPECT_EQ(psoInertia(i_max, i_max, w_max, w_min), w_min);  // exact: the last iteration uses w_min
  EXPECT_EQ(psoInertia(0, i_max, w_max, w_min), w_max);
  for (int i = 1; i <= i_max; ++i)
    EXPECT_LT(psoInertia(i, i_max, w_max, w_min), psoInertia(i - 1, i_max, w_max, w_min)) << "i = " << i;
}

// ---- validation ----------------------------------------------------------------------------------

TEST(PsoValidate, AcceptsDefaultsWithBounds) {
  PsoParams p;
  p.lower = {0.0, -1.0};
  p.upper = {1.0, 1.0};
  EXPECT_EQ(p.validate(), "");
}

TEST(PsoValidate, RejectsBadBoundsAndSizes) {
  PsoParams p;
  EXPECT_NE(p.validate().find("empty"), std::string::npos) << p.validate();

  p.lower = {0.0, 0.0};
  p.upper = {1.0};
  EXPECT_NE(p.validate().find("lower has 2 entries"), std::string::npos) << p.validate();

  p.lower = {0.0, 1.0};
  p.upper = {1.0, 1.0};  // lower == upper
  EXPECT_NE(p.validate().find("lower[1]"), std::string::npos) << p.validate();

  p.lower = {2.0, 0.0};
  p.upper = {1.0, 1.0};  // lower > upper
  EXPECT_NE(p.validate().find("lower[0]"), std::string::npos) << p.validate();

  const double nan = std::numeric_limits<double>::quiet_NaN();
  p.lower = {0.0, nan};
  p.upper = {1.0, 1.0};
  EXPECT_NE(p.validate().find("lower[1]"), std::string::npos) << p.validate();
  p.lower = {0.0, 0.0};
  p.upper = {nan, 1.0};
  EXPECT_NE(p.validate().find("upper[0]"), std::string::npos) << p.validate();
  p.upper = {std::numeric_limits<double>::infinity(), 1.0};
  EXPECT_NE(p.validate(), "");
}

TEST(PsoValidate, RejectsBadScalars) {
  PsoParams p = boxParams(2, -1.0, 1.0, 20, 30);
  ASSERT_EQ(p.validate(), "");
  auto rejects = [&](auto mutate, const std::string& name) {
    PsoParams q = p;
    mutate(q);
    const std::string e = q.validate();
    EXPECT_NE(e.find(name), std::string::npos) << "expected a message naming " << name << ", got: " << e;
  };
  rejects([](PsoParams& q) { q.particles = 0; }, "particles");
  rejects([](PsoParams& q) { q.iterations = -1; }, "iterations");
  rejects([](PsoParams& q) { q.w_max = 0.05; }, "w_max");  // below w_min
  rejects([](PsoParams& q) { q.w_min = -0.1; }, "w_min");
  rejects([](PsoParams& q) { q.c1 = std::numeric_limits<double>::quiet_NaN(); }, "c1");
  rejects([](PsoParams& q) { q.c2 = -1.0; }, "c2");
  rejects([](PsoParams& q) { q.max_velocity_fraction = -0.5; }, "max_velocity_fraction");
  rejects([](PsoParams& q) { q.threads = -1; }, "threads");
}

TEST(PsoMinimize, ThrowsOnInvalidParams) {
  PsoParams p = boxParams(2, -1.0, 1.0, 20, 30);
  p.particles = 0;
  EXPECT_THROW(psoMinimize(p, [](const std::vector<double>& x, int) { return sphere(x); }), std::invalid_argument);
}

// ---- convergence ---------------------------------------------------------------------------------

// Sphere in [-5.12, 5.12]^D with 30 particles x 100 iterations: best cost < 1e-6 (D = 2 and 5).
TEST(PsoMinimize, SphereReachesMinimum) {
  for (std::size_t dims : {2u, 5u}) {
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      const PsoParams p = boxParams(dims, -5.12, 5.12, 30, 100, seed);
      const PsoResult r = psoMinimize(p, [](const std::vector<double>& x, int) { return sphere(x); });
      EXPECT_LT(r.best_cost, 1e-6) << "D = " << dims << ", seed = " << seed;
      ASSERT_EQ(r.best_position.size(), dims);
      EXPECT_DOUBLE_EQ(r.best_cost, sphere(r.best_position));
      for (double v : r.best_position) EXPECT_LT(std::abs(v), 1e-3);
    }
  }
}

// Rosenbrock 2-D in [-2.048, 2.048]^2 with 30 particles x 200 iterations: best cost < 1e-3, at (1, 1).
TEST(PsoMinimize, Rosenbrock2DReachesMinimum) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const PsoParams p = boxParams(2, -2.048, 2.048, 30, 200, seed);
    const PsoResult r = psoMinimize(p, [](const std::vector<double>& x, int) { return rosenbrock2(x); });
    EXPECT_LT(r.best_cost, 1e-3) << "seed = " << seed;
    EXPECT_NEAR(r.best_position[0], 1.0, 0.1);
    EXPECT_NEAR(r.best_position[1], 1.0, 0.2);
  }
}

// ---- bounds and velocity clamp -------------------------------------------------------------------

// The minimum of sum(x) lies in the lower corner and the swarm overshoots it, so positions get clamped.
TEST(PsoMinimize, EveryEvaluatedPositionIsInsideTheBox) {
  PsoParams p = boxParams(3, 0.0, 1.0, 20, 40, 7, 2);
  p.lower = {-1.0, 0.0, 10.0};
  p.upper = {1.0, 0.5, 20.0};
  Recorder rec(p.threads);
  const PsoResult r = psoMinimize(p, [&](const std::vector<double>& x, int t) {
    EXPECT_GE(t, 0);
    EXPECT_LT(t, p.threads);
    rec.per_thread[static_cast<std::size_t>(t)].push_back(x);
    return x[0] + x[1] + x[2];
  });
  const auto all = rec.all();
  ASSERT_EQ(static_cast<long>(all.size()), r.evaluations);
  int on_lower_bound = 0;
  for (const auto& x : all) {
    ASSERT_EQ(x.size(), 3u);
    for (std::size_t d = 0; d < 3; ++d) {
      EXPECT_GE(x[d], p.lower[d]);
      EXPECT_LE(x[d], p.upper[d]);
      on_lower_bound += x[d] == p.lower[d];
    }
  }
  EXPECT_GT(on_lower_bound, 0) << "the clamp was never exercised";
  for (std::size_t d = 0; d < 3; ++d) EXPECT_EQ(r.best_position[d], p.lower[d]);
}

// With threads = 1 particle j of iteration i is evaluation i * particles + j, so steps can be measured.
TEST(PsoMinimize, VelocityClampLimitsEveryStep) {
  PsoParams p = boxParams(2, -5.12, 5.12, 10, 20, 3, 1);
  p.max_velocity_fraction = 0.05;
  const double v_max = 0.05 * 10.24;
  std::vector<std::vector<double>> seen;
  psoMinimize(p, [&](const std::vector<double>& x, int) {
    seen.push_back(x);
    return rastrigin(x);
  });
  const std::size_t n = static_cast<std::size_t>(p.particles);
  ASSERT_EQ(seen.size(), n * static_cast<std::size_t>(p.iterations + 1));
  double largest = 0.0;
  for (std::size_t k = n; k < seen.size(); ++k)
    for (std::size_t d = 0; d < 2; ++d) largest = std::max(largest, std::abs(seen[k][d] - seen[k - n][d]));
  EXPECT_LE(largest, v_max * (1.0 + 1e-12));
  EXPECT_GT(largest, 0.5 * v_max);  // the clamp is active, not everything frozen

  // Without the clamp the same swarm takes much larger steps (so the check above can fail).
  p.max_velocity_fraction = 0.0;
  seen.clear();
  psoMinimize(p, [&](const std::vector<double>& x, int) {
    seen.push_back(x);
    return rastrigin(x);
  });
  largest = 0.0;
  for (std::size_t k = n; k < seen.size(); ++k)
    for (std::size_t d = 0; d < 2; ++d) largest = std::max(largest, std::abs(seen[k][d] - seen[k - n][d]));
  EXPECT_GT(largest, 2.0 * v_max);
}

// ---- determinism ---------------------------------------------------------------------------------

TEST(PsoMinimize, SameSeedIsBitIdenticalForAnyThreadCount) {
  auto run = [](std::uint64_t seed, int threads) {
    const PsoParams p = boxParams(4, -5.12, 5.12, 20, 30, seed, threads);
    return psoMinimize(p, [](const std::vector<double>& x, int) { return rastrigin(x); });
  };
  const PsoResult a = run(42, 1);
  const PsoResult b = run(42, 1);
  const PsoResult c = run(42, 2);
  const PsoResult d = run(42, 3);
  for (const PsoResult* o : {&b, &c, &d}) {
    EXPECT_EQ(o->best_cost, a.best_cost);
    EXPECT_EQ(o->best_position, a.best_position);
    EXPECT_EQ(o->best_cost_per_iteration, a.best_cost_per_iteration);
    EXPECT_EQ(o->evaluations, a.evaluations);
  }
  const PsoResult e = run(43, 2);
  EXPECT_NE(e.best_position, a.best_position);
  EXPECT_NE(e.best_cost_per_iteration, a.best_cost_per_iteration);
}

// The sequence of evaluated positions (not only the result) is the same with 1 and 2 threads.
TEST(PsoMinimize, EvaluatedPositionsDoNotDependOnThreads) {
  auto positions = [](int threads) {
    const PsoParams p = boxParams(2, -2.048, 2.048, 8, 10, 5, threads);
    std::mutex m;
    std::vector<std::vector<double>> seen;
    psoMinimize(p, [&](const std::vector<double>& x, int) {
      std::lock_guard<std::mutex> lock(m);
      seen.push_back(x);
      return rosenbrock2(x);
    });
    std::sort(seen.begin(), seen.end());  // evaluation order within an iteration differs between threads
    return seen;
  };
  EXPECT_EQ(positions(1), positions(2));
}

// ---- bookkeeping ---------------------------------------------------------------------------------

TEST(PsoMinimize, HistoryIsNonIncreasingAndEvaluationsAreCounted) {
  const PsoParams p = boxParams(3, -5.12, 5.12, 20, 30, 9, 2);
  std::atomic<long> calls{0};
  const PsoResult r = psoMinimize(p, [&](const std::vector<double>& x, int) {
    ++calls;
    return rastrigin(x);
  });
  EXPECT_EQ(r.evaluations, 20L * (30 + 1));
  EXPECT_EQ(calls.load(), r.evaluations);
  ASSERT_EQ(r.best_cost_per_iteration.size(), 31u);
  for (std::size_t i = 1; i < r.best_cost_per_iteration.size(); ++i)
    EXPECT_LE(r.best_cost_per_iteration[i], r.best_cost_per_iteration[i - 1]) << "iteration " << i;
  EXPECT_LT(r.best_cost_per_iteration.back(), r.best_cost_per_iteration.front());  // it did improve
  EXPECT_EQ(r.best_cost_per_iteration.back(), r.best_cost);
  EXPECT_EQ(r.best_cost, rastrigin(r.best_position));
}

TEST(PsoMinimize, ProgressIsReportedOnTheCallerThreadForEveryIteration) {
  const PsoParams p = boxParams(2, -5.12, 5.12, 10, 12, 1, 2);
  const auto caller = std::this_thread::get_id();
  std::vector<int> iterations;
  std::vector<double> costs;
  const PsoResult r = psoMinimize(
      p, [](const std::vector<double>& x, int) { return sphere(x); },
      [&](const PsoProgress& pr) {
        EXPECT_EQ(std::this_thread::get_id(), caller);
        EXPECT_EQ(pr.iterations, 12);
        ASSERT_NE(pr.best_position, nullptr);
        EXPECT_EQ(sphere(*pr.best_position), pr.best_cost);
        EXPECT_GE(pr.elapsed_s, 0.0);
        EXPECT_GE(pr.eta_s, 0.0);
        if (pr.iteration == pr.iterations) {
          EXPECT_EQ(pr.eta_s, 0.0);
        }
        iterations.push_back(pr.iteration);
        costs.push_back(pr.best_cost);
      });
  ASSERT_EQ(iterations.size(), 13u);
  for (int i = 0; i <= 12; ++i) EXPECT_EQ(iterations[static_cast<std::size_t>(i)], i);
  EXPECT_EQ(costs, r.best_cost_per_iteration);
}

TEST(PsoMinimize, NonFiniteCostNeverBecomesBest) {
  // NaN / inf everywhere with x[0] > 0: the best must be on the finite side.
  const PsoParams p = boxParams(2, -1.0, 1.0, 20, 30, 4, 2);
  const PsoResult r = psoMinimize(p, [](const std::vector<double>& x, int) {
    if (x[0] > 0.0)
      return x[1] > 0.0 ? std::numeric_limits<double>::quiet_NaN() : -std::numeric_limits<double>::infinity();
    return sphere(x) + 1.0;
  });
  EXPECT_LE(r.best_position[0], 0.0);
  EXPECT_TRUE(std::isfinite(r.best_cost));
  EXPECT_GE(r.best_cost, 1.0);

  // Nothing finite at all: +inf, and the position is still inside the box.
  const PsoResult none =
      psoMinimize(p, [](const std::vector<double>&, int) { return std::numeric_limits<double>::quiet_NaN(); });
  EXPECT_EQ(none.best_cost, std::numeric_limits<double>::infinity());
  for (double c : none.best_cost_per_iteration) EXPECT_EQ(c, std::numeric_limits<double>::infinity());
  ASSERT_EQ(none.best_position.size(), 2u);
  for (double v : none.best_position) {
    EXPECT_GE(v, -1.0);
    EXPECT_LE(v, 1.0);
  }
}

// With a constant cost nothing is ever strictly better, so the first evaluated position stays the best.
TEST(PsoMinimize, TiesKeepTheOlderGlobalBest) {
  const PsoParams p = boxParams(2, -1.0, 1.0, 10, 10, 11, 1);
  std::vector<std::vector<double>> seen;
  const PsoResult r = psoMinimize(p, [&](const std::vector<double>& x, int) {
    seen.push_back(x);
    return 3.0;
  });
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(r.best_position, seen.front());
  EXPECT_EQ(r.best_cost, 3.0);
}

// Personal-best ties: with a constant cost, w = 0 and two particles in 1-D, particle 1 moves by
// x' - g = (1 - 2 r1 - 2 r2)(x - g) + 2 r1 (p - g) with p its first position. If a tie replaced p with
// the current position, this would shrink to x' - g = (1 - 2 r2)(x - g) and collapse onto g.
TEST(PsoMinimize, TiesKeepTheOlderPersonalBest) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    PsoParams p = boxParams(1, -1.0, 1.0, 2, 60, seed, 1);
    p.w_max = p.w_min = 0.0;
    std::vector<double> seen;
    psoMinimize(p, [&](const std::vector<double>& x, int) {
      seen.push_back(x[0]);
      return 0.0;
    });
    ASSERT_EQ(seen.size(), 2u * 61u);
    const double g = seen[0];  // particle 0's start: the global best for ever (ties keep it)
    EXPECT_EQ(seen[seen.size() - 2], g) << "particle 0 sits on its own (= global) best";
    double late_distance = 0.0;  // particle 1 over the last 10 iterations
    for (std::size_t k = seen.size() - 20; k < seen.size(); k += 2) late_distance += std::abs(seen[k + 1] - g);
    EXPECT_GT(late_distance, 1e-3) << "seed " << seed << ": particle 1 collapsed onto the global best";
  }
}

TEST(PsoMinimize, FitnessExceptionIsRethrownOnCaller) {
  const PsoParams p = boxParams(2, -1.0, 1.0, 10, 10, 1, 2);
  std::atomic<int> calls{0};
  EXPECT_THROW(psoMinimize(p,
                           [&](const std::vector<double>& x, int) {
                             if (++calls == 25) throw std::runtime_error("boom");
                             return sphere(x);
                           }),
               std::runtime_error);
  EXPECT_LT(calls.load(), 10 * 11);  // stopped early
}

TEST(PsoMinimize, MoreThreadsThanParticlesIsFine) {
  PsoParams p = boxParams(2, -5.12, 5.12, 3, 5, 1, 8);
  std::atomic<int> max_index{-1};
  const PsoResult r = psoMinimize(p, [&](const std::vector<double>& x, int t) {
    int m = max_index.load();
    while (t > m && !max_index.compare_exchange_weak(m, t)) {
    }
    return sphere(x);
  });
  EXPECT_LT(max_index.load(), 3);  // thread_index < min(threads, particles)
  p.threads = 1;
  EXPECT_EQ(psoMinimize(p, [](const std::vector<double>& x, int) { return sphere(x); }).best_position, r.best_position);
}

TEST(PsoMinimize, BoundedFitnessSearchesExactlyLikeTheExactOne) {
  // A fitness that gives up as soon as it cannot beat the particle's personal best (and then returns
  // some value >= bound, not its cost) must leave the whole search unchanged.
  PsoParams p;
  p.particles = 12;
  p.iterations = 25;
  p.lower = {-5.0, -5.0, -5.0};
  p.upper = {5.0, 5.0, 5.0};
  p.seed = 11;
  p.threads = 2;
  std::atomic<int> cut{0};
  const PsoResult exact = psoMinimize(p, [](const std::vector<double>& x, int) { return rastrigin(x); });
  const PsoResult bounded = psoMinimize(p, PsoBoundedFitness([&cut](const std::vector<double>& x, int, double bound) {
                                          const double c = rastrigin(x);
                                          if (c < bound) return c;
                                          ++cut;
                                          return bound + 1.0;  // "at least the bound"
                                        }));
  EXPECT_GT(cut.load(), 0);
  EXPECT_EQ(bounded.best_position, exact.best_position);
  EXPECT_EQ(bounded.best_cost, exact.best_cost);
  EXPECT_EQ(bounded.best_cost_per_iteration, exact.best_cost_per_iteration);
}

TEST(PsoMinimize, BoundIsThePersonalBest) {
  PsoParams p;
  p.particles = 1;
  p.iterations = 3;
  p.lower = {-1.0};
  p.upper = {1.0};
  p.threads = 1;
  std::vector<double> bounds, costs;
  psoMinimize(p, PsoBoundedFitness([&](const std::vector<double>& x, int, double bound) {
                bounds.push_back(bound);
                costs.push_back(sphere(x));
                return costs.back();
              }));
  ASSERT_EQ(bounds.size(), 4u);
  EXPECT_TRUE(std::isinf(bounds[0]));  // no personal best before the first evaluation
  double best = costs[0];
  for (std::size_t i = 1; i < bounds.size(); ++i) {
    EXPECT_EQ(bounds[i], best) << i;
    best = std::min(best, costs[i]);
  }
}
