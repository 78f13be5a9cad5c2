// TuningProblem: the PSO tuner's objective, and its bound (a run stops once it cannot beat the bound).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sowing_robot/core/evaluation/tuning.h"

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

namespace {
Scenario pair(const std::string& name) {
  Scenario sc = shortThesisRun();
  const std::string e = parseControllerPair(name, sc.outer, sc.inner, sc.sliding.adaptive);
  EXPECT_EQ(e, "") << name;
  return sc;
}
using Names = std::vector<std::string>;
}  // namespace

TEST(TunableGains, EachPairSearchesItsTablesMarks) {
  EXPECT_EQ(tunableGainNames(pair("kanayama+atsmc")),
            (Names{"kx", "ky", "ktheta", "beta_v", "beta_omega", "k1", "k2", "eta1", "eta2", "rate_m", "rate_i"}));
  // TSMC does not adapt: its rates are no search dimension.
  EXPECT_EQ(tunableGainNames(pair("kanayama+tsmc")),
            (Names{"kx", "ky", "ktheta", "beta_v", "beta_omega", "k1", "k2", "eta1", "eta2"}));
  EXPECT_EQ(tunableGainNames(pair("kanayama+pid")), (Names{"kx", "ky", "ktheta", "kp", "ki", "kd", "feedforward"}));
  EXPECT_EQ(tunableGainNames(pair("rpp+pid")), (Names{"lookahead_dist", "regulated_linear_scaling_min_radius",
                                                      "k_along", "kp", "ki", "kd", "feedforward"}));
  // Plain pure pursuit has no regulation radius.
  EXPECT_EQ(tunableGainNames(pair("pure_pursuit+pid")),
            (Names{"lookahead_dist", "k_along", "kp", "ki", "kd", "feedforward"}));
  EXPECT_EQ(tunableGainNames(), tunableGainNames(Scenario()));
}

TEST(TunableGains, EveryMarkHasSearchBoundsTheControllerAccepts) {
  for (const char* name : {"kanayama+atsmc", "kanayama+tsmc", "kanayama+pid", "rpp+pid", "rpp+atsmc"}) {
    const Scenario sc = pair(name);
    const std::vector<GainBounds> box = defaultGainBounds(sc);
    ASSERT_EQ(box.size(), tunableGainNames(sc).size()) << name;
    for (const GainBounds& b : box) EXPECT_TRUE(b.lower < b.upper) << name << " " << b.name;
    EXPECT_EQ(validateGainBounds(sc, box), "") << name;
  }
  EXPECT_TRUE(std::isnan(gainSearchBounds("bogus").lower));
}

TEST(TunableGains, SetAndGetReachThePairsOwnParameters) {
  Scenario sc = pair("rpp+pid");
  EXPECT_TRUE(setGain(sc, "lookahead_dist", 0.45));
  EXPECT_EQ(sc.pure_pursuit.lookahead_dist, 0.45);
  EXPECT_TRUE(setGain(sc, "kp", 7.0));
  EXPECT_EQ(sc.pid.kp, 7.0);
  EXPECT_EQ(getGain(sc, "kp"), 7.0);
  EXPECT_FALSE(setGain(sc, "kx", 2.0));  // not a gain of rpp+pid
  EXPECT_TRUE(std::isnan(getGain(sc, "k1")));
  EXPECT_EQ(gainNode(sc, "kp"), "torque_controller");
  EXPECT_EQ(gainKey(sc, "kp"), "kp");  // flat under the node, as the nodes read it
  EXPECT_EQ(gainKey(sc, "lookahead_dist"), "lookahead_dist");
  EXPECT_NE(validateGainBounds(sc, {{"kx", 0.1, 10.0}}).find("no tunable gain of rpp+pid"), std::string::npos);
}

TEST(TunableGains, ControllerParamsByNodeKey) {
  Scenario sc;
  EXPECT_EQ(setControllerParam(sc, "torque_controller", "adaptation", std::string("eq_4_22")), "");
  EXPECT_EQ(sc.sliding.adaptation, Adaptation::eq_4_22);
  EXPECT_EQ(setControllerParam(sc, "torque_controller", "ki", 3), "");  // an int for a double
  EXPECT_EQ(sc.pid.ki, 3.0);
  EXPECT_EQ(setControllerParam(sc, "kinematic_controller", "k_along", 1.5), "");
  EXPECT_EQ(sc.pure_pursuit.k_along, 1.5);
  EXPECT_NE(setControllerParam(sc, "kinematic_controller", "kz", 1.0), "");
  EXPECT_NE(setControllerParam(sc, "torque_controller", "k1", -1.0), "");
  EXPECT_NE(setControllerParam(sc, "plant_sim", "k1", 1.0), "");
  EXPECT_EQ(setControllerParam(sc, "torque_controller", "max_torque", 50.0), "");  // the one motor limit
  EXPECT_EQ(sc.sliding.max_torque, 50.0);
  EXPECT_EQ(sc.pid.max_torque, 50.0);
}

TEST(GainsYaml, KeysAreTheNodesAndNamesTheVariant) {
  Scenario sc = pair("rpp+pid");
  const std::string y = gainsYaml(sc, {{"kp", 0.0, 50.0}});
  EXPECT_NE(y.find("kinematic_controller:\n  lookahead_dist: 0.6"), std::string::npos) << y;
  EXPECT_NE(y.find("torque_controller:\n  kp: 2.0"), std::string::npos) << y;
  EXPECT_NE(y.find("# tuned in [0, 50]"), std::string::npos) << y;
  Scenario a = pair("kanayama+atsmc");
  EXPECT_EQ(gainsYaml(a, {}).find("adaptation"), std::string::npos);  // default reading: gains only
  a.sliding.adaptation = Adaptation::eq_4_22;
  EXPECT_NE(gainsYaml(a, {}).find("  adaptation: eq_4_22"), std::string::npos);
}
