// TuningProblem: the PSO tuner's objective, and its bound (a run stops once it cannot beat the bound).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sowing_robot/core/tuning.h"

using namespace sowing_robot::core;

namespace {
Scenario shortThesisRun() {
  Scenario sc;
  sc.duration = 5.0;
  sc.disturbance.sinusoidal = true;
  sc.disturbance.mass_scale = sc.disturbance.inertia_scale = 1.2;
  return sc;
}
}  // namespace

TEST(TuningProblem, BoundStopsARunThatCannotBeatIt) {
  LineReference ref;
  TuningObjective objective;
  objective.torque_weight = 1e-4;  // every term in play
  objective.chattering_weight = 1e-3;
  const TuningProblem problem(shortThesisRun(), ref, defaultGainBounds(), objective, 1);
  const std::vector<double> x{1.0, 1.5, 2.2, 150.0, 150.0, 2.0, 2.0};
  const TuningCost exact = problem.evaluate(x, 0);
  ASSERT_TRUE(std::isfinite(exact.total));
  EXPECT_FALSE(exact.bounded);

  const TuningCost cut = problem.evaluate(x, 0, 0.5 * exact.total);
  EXPECT_TRUE(cut.bounded);
  EXPECT_GE(cut.total, 0.5 * exact.total);  // "at least the bound": the particle cannot improve
  EXPECT_LE(cut.total, exact.total);        // and never above the whole run's cost

  const TuningCost beaten = problem.evaluate(x, 0, 2.0 * exact.total);  // a bound it beats: run whole
  EXPECT_FALSE(beaten.bounded);
  EXPECT_EQ(beaten.total, exact.total);
  // A bound equal to the exact cost may stop the run only in its last checks, never below it.
  const TuningCost tie = problem.evaluate(x, 0, exact.total);
  EXPECT_GE(tie.total, exact.total);
}

TEST(TuneGains, BoundedSearchFindsTheSameGainsAsTheExactOne) {
  // tuneGains evaluates with the bound; the same PSO with exact evaluations must end identically.
  LineReference ref;
  const Scenario sc = shortThesisRun();
  TuningObjective objective;
  PsoParams p;
  p.particles = 6;
  p.iterations = 5;
  p.seed = 5;
  p.threads = 2;
  const std::vector<GainBounds> gains = defaultGainBounds();
  const TuningResult tuned = tuneGains(sc, ref, gains, objective, p);

  const TuningProblem problem(sc, ref, gains, objective, 2);
  for (const GainBounds& g : gains) {
    p.lower.push_back(g.lower);
    p.upper.push_back(g.upper);
  }
  const PsoResult exact =
      psoMinimize(p, [&problem](const std::vector<double>& x, int t) { return problem.evaluate(x, t).total; });
  EXPECT_EQ(tuned.pso.best_position, exact.best_position);
  EXPECT_EQ(tuned.pso.best_cost, exact.best_cost);
  EXPECT_EQ(tuned.pso.best_cost_per_iteration, exact.best_cost_per_iteration);
}
