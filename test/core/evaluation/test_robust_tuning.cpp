// Robust tuning: the cost of one training run (tracking term capped, a failure's penalty
// on top), the set's mean and quantile, that evaluating the whole set equals combining its runs one by one
// (what the MPI farm does), that a bounded evaluation never hides a better cost, and that the search over a
// training set gives the same gains for any thread count and improves on its initial swarm.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include "sowing_robot/core/evaluation/robust_tuning.h"

using namespace sowing_robot::core;

namespace {

/// A short line scenario of the benchmark (no-slip plant, the tables' kanayama+pid), `seconds` long.
BenchScenario shortLine(const std::string& name, double seconds, double line_y) {
  BenchScenario b;
  b.name = name;
  b.track = TrackKind::line;
  b.base.duration = seconds;
  b.base.outer = OuterKind::kanayama;
  b.base.inner = InnerKind::pid;
  b.line_y = line_y;
  b.spec.settle_time = 0.5 * seconds;
  return b;
}

std::vector<TrainingScenario> smallSet() { return {{shortLine("a", 3.0, 3.0), 3}, {shortLine("b", 2.0, 1.0), 2}}; }

std::vector<GainBounds> kanayamaGains() { return {{"kx", 0.1, 10.0}, {"ky", 0.1, 10.0}, {"ktheta", 0.1, 10.0}}; }

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST(RobustTuning, RunCostIsTheCappedTrackingTermPlusThePenaltyOfAFailure) {
  RobustObjective o;
  o.failure_penalty = 0.5;
  RunRow row;
  row.metrics[AXIS_X].itae = 1.0;
  row.metrics[AXIS_Y].itae = 2.0;
  row.metrics[AXIS_THETA].itae = 2.0;
  row.success = true;
  EXPECT_DOUBLE_EQ(2.0 * 5.0 / 100.0, trainingRunCost(row, 10.0, o));  // 2 ITAE / T^2
  row.success = false;
  EXPECT_DOUBLE_EQ(0.1 + 0.5, trainingRunCost(row, 10.0, o));
  row.metrics[AXIS_Y].itae = std::numeric_limits<double>::infinity();  // diverged: the cap, then the penalty
  EXPECT_DOUBLE_EQ(1.0, trainingRunCost(row, 10.0, o));
  row.metrics[AXIS_Y].itae = std::numeric_limits<double>::quiet_NaN();
  EXPECT_DOUBLE_EQ(1.0, trainingRunCost(row, 10.0, o));
}

// max_slip_share: a success whose wheels spent longer beyond twice the peak's slip costs the penalty too; off
// (1), or a run without the traction plant (no share: NaN), only the benchmark's rule counts.
TEST(RobustTuning, ASlipShareLimitMakesASlippingSuccessAFailure) {
  RobustObjective o;
  RunRow row;
  row.metrics[AXIS_Y].itae = 5.0;
  row.success = true;
  row.high_slip_share = 0.08;
  EXPECT_DOUBLE_EQ(0.1, trainingRunCost(row, 10.0, o));
  o.max_slip_share = 0.05;
  EXPECT_EQ("", o.validate());
  EXPECT_DOUBLE_EQ(0.1 + 1.0, trainingRunCost(row, 10.0, o));
  row.high_slip_share = 0.05;  // at the limit: within it
  EXPECT_DOUBLE_EQ(0.1, trainingRunCost(row, 10.0, o));
  row.high_slip_share = std::numeric_limits<double>::quiet_NaN();
  EXPECT_DOUBLE_EQ(0.1, trainingRunCost(row, 10.0, o));
  row.success = false;  // one penalty for a run that fails both ways
  row.high_slip_share = 0.5;
  EXPECT_DOUBLE_EQ(0.1 + 1.0, trainingRunCost(row, 10.0, o));
  o.max_slip_share = 0.0;
  EXPECT_NE(o.validate().find("robust/max_slip_share"), std::string::npos);
}

TEST(RobustTuning, MeanAndQuantileOfTheRuns) {
  RobustObjective o;
  const RobustTuningProblem mean(smallSet(), kanayamaGains(), o, 1);
  EXPECT_EQ(5, mean.runCount());
  EXPECT_DOUBLE_EQ(0.3, mean.combine({0.1, 0.2, 0.3, 0.4, 0.5}).total);
  EXPECT_DOUBLE_EQ(3.0 + 3.0 + 3.0 + 2.0 + 2.0, mean.combine({0.1, 0.2, 0.3, 0.4, 0.5}).simulated);
  o.aggregate = RobustObjective::Aggregate::quantile;
  o.quantile = 0.8;  // nearest rank: the 4th of 5
  const RobustTuningProblem q(smallSet(), kanayamaGains(), o, 1);
  EXPECT_DOUBLE_EQ(0.4, q.combine({0.5, 0.1, 0.4, 0.2, 0.3}).total);
  o.quantile = 1.0;
  EXPECT_DOUBLE_EQ(0.5,
                   RobustTuningProblem(smallSet(), kanayamaGains(), o, 1).combine({0.5, 0.1, 0.4, 0.2, 0.3}).total);
}

TEST(RobustTuning, TheWholeSetIsItsRunsCombinedAndEachRunIsTheBenchmarksRow) {
  const RobustTuningProblem p(smallSet(), kanayamaGains(), RobustObjective(), 1);
  const std::vector<double> x{2.0, 3.0, 4.0};
  std::vector<double> runs;
  for (std::int64_t k = 0; k < p.runCount(); ++k) runs.push_back(p.runCost(x, k));
  const TuningCost whole = p.evaluate(x, 0);
  EXPECT_TRUE(sameBits(p.combine(runs).total, whole.total));
  EXPECT_FALSE(whole.bounded);
  // Run 3 is scenario b's run 0: the benchmark's row of b with these gains.
  BenchScenario b = smallSet()[1].bench;
  setGain(b.base, "kx", 2.0);
  setGain(b.base, "ky", 3.0);
  setGain(b.base, "ktheta", 4.0);
  EXPECT_TRUE(sameBits(trainingRunCost(runBenchmark(b, 1, 1)[0], 2.0, RobustObjective()), runs[3]));
  // Other gains, another cost: the gains reach the runs.
  EXPECT_FALSE(sameBits(p.runCost({0.5, 0.5, 0.5}, 3), runs[3]));
}

TEST(RobustTuning, ABoundedEvaluationStopsOnlyAtOrAboveItsBound) {
  const RobustTuningProblem p(smallSet(), kanayamaGains(), RobustObjective(), 1);
  const std::vector<double> x{0.2, 0.2, 0.2};
  const double exact = p.evaluate(x, 0).total;
  const TuningCost low = p.evaluate(x, 0, 0.25 * exact);  // cannot beat this bound: may stop early
  EXPECT_TRUE(low.bounded);
  EXPECT_GE(low.total, 0.25 * exact);
  EXPECT_LE(low.total, exact);
  const TuningCost high = p.evaluate(x, 0, 2.0 * exact);  // can beat it: the exact cost
  EXPECT_FALSE(high.bounded);
  EXPECT_TRUE(sameBits(exact, high.total));
}

TEST(RobustTuning, SameGainsForAnyThreadCountAndBetterThanTheInitialSwarm) {
  PsoParams pso;
  pso.particles = 6;
  pso.iterations = 3;
  pso.seed = 5;
  std::vector<std::vector<double>> best;
  for (int threads : {1, 2}) {
    pso.threads = threads;
    TuningSession s(std::make_unique<RobustTuningProblem>(smallSet(), kanayamaGains(), RobustObjective(), threads),
                    pso);
    const TuningBatch batch = threadedTuningBatch(s.problem(), s.params());
    while (!s.finished()) s.step(batch);
    const TuningResult r = s.result();
    EXPECT_LE(r.pso.best_cost, r.initial_best_cost);
    EXPECT_TRUE(sameBits(r.pso.best_cost, r.best.total));  // the best re-evaluated: the same cost
    best.push_back(r.best_gains);
  }
  ASSERT_EQ(best[0].size(), best[1].size());
  for (std::size_t d = 0; d < best[0].size(); ++d) EXPECT_TRUE(sameBits(best[0][d], best[1][d]));
}

TEST(RobustTuning, BadSetsAndObjectivesAreRefusedWithOneLine) {
  RobustObjective o;
  EXPECT_THROW(RobustTuningProblem({}, kanayamaGains(), o, 1), std::invalid_argument);
  auto set = smallSet();
  set[1].runs = 0;
  EXPECT_THROW(RobustTuningProblem(set, kanayamaGains(), o, 1), std::invalid_argument);
  EXPECT_THROW(RobustTuningProblem(smallSet(), {{"kx", 1.0, 0.5}}, o, 1), std::invalid_argument);
  EXPECT_THROW(RobustTuningProblem(smallSet(), {{"kp", 0.0, 1.0}, {"nonsense", 0.0, 1.0}}, o, 1),
               std::invalid_argument);
  o.failure_penalty = 0.0;
  EXPECT_NE("", o.validate());
  o = RobustObjective();
  o.aggregate = RobustObjective::Aggregate::quantile;
  o.quantile = 0.0;
  EXPECT_NE("", o.validate());
  RobustObjective::Aggregate a;
  EXPECT_TRUE(parseAggregate("quantile", a));
  EXPECT_FALSE(parseAggregate("median", a));
}
