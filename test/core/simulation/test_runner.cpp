// The in-process closed loop on the thesis scenario (xd = t, yd = 3, start (-1, 0, 0), 25 s).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include "sowing_robot/core/simulation/runner.h"

using namespace sowing_robot::core;

namespace {
struct Worst {
  double ey = 0, eth = 0, ex = 0;
};
Worst worstAfter(const Scenario& sc, double t0) {
  LineReference ref;
  Worst w;
  runClosedLoop(sc, ref, false, [&](const LoopSample& s) {
    if (s.t < t0) return;
    w.ex = std::max(w.ex, std::fabs(s.ex));
    w.ey = std::max(w.ey, std::fabs(s.ey));
    w.eth = std::max(w.eth, std::fabs(s.etheta));
  });
  return w;
}
}  // namespace

TEST(Runner, WithoutDisturbanceTheErrorConvergesAndStays) {
  for (bool adaptive : {true, false}) {
    Scenario sc;
    sc.sliding.adaptive = adaptive;
    const Worst w = worstAfter(sc, 12.0);  // from 12 s to the end at 25 s
    EXPECT_LT(w.ex, 0.01) << adaptive;
    EXPECT_LT(w.ey, 0.01) << adaptive;
    EXPECT_LT(w.eth, 0.01) << adaptive;
  }
}

TEST(Runner, DisturbanceAndMismatchKeepTheLateralErrorSmall) {
  Scenario sc;
  sc.disturbance.sinusoidal = true;
  sc.disturbance.mass_scale = sc.disturbance.inertia_scale = 1.2;
  LineReference ref;
  const RunResult r = runClosedLoop(sc, ref);
  EXPECT_FALSE(r.diverged);
  EXPECT_LT(std::fabs(r.final_state[Y] - 3.0), 0.02);
  EXPECT_LT(std::fabs(r.final_state[THETA]), 0.02);
}

TEST(Runner, RepeatsBitForBitWithTheSameSeed) {
  Scenario sc;
  sc.disturbance.sinusoidal = true;
  sc.disturbance.noise_std = 0.3;
  sc.disturbance.seed = 42;
  sc.duration = 5.0;
  LineReference ref;
  const RunResult a = runClosedLoop(sc, ref), b = runClosedLoop(sc, ref);
  EXPECT_EQ(a.final_state, b.final_state);
  for (int k = 0; k < AXIS_COUNT; ++k) EXPECT_EQ(a.metrics[k].itae, b.metrics[k].itae);
  sc.disturbance.seed = 43;
  EXPECT_NE(runClosedLoop(sc, ref).final_state, a.final_state);
}

TEST(Runner, DivergenceIsReportedNotHidden) {
  Scenario sc;
  sc.duration = 2.0;
  sc.sliding.k2 = 1e6;  // far beyond what a 1 ms step can integrate
  sc.sliding.max_torque = 1e9;
  LineReference ref;
  const RunResult r = runClosedLoop(sc, ref, false);
  EXPECT_TRUE(r.diverged);
  EXPECT_TRUE(std::isinf(r.metrics[AXIS_Y].itae));
}

TEST(Runner, ScenarioValidation) {
  Scenario sc;
  EXPECT_TRUE(sc.validate().empty());
  EXPECT_EQ(sc.steps(), 25000);
  sc.duration = -1;
  EXPECT_NE(sc.validate().find("duration"), std::string::npos);
}

TEST(Runner, StopEndsTheRunWithTheIntegralsSoFar) {
  Scenario sc;
  sc.duration = 5.0;
  LineReference ref;
  const RunResult whole = runClosedLoop(sc, ref, false);
  int asked = 0;
  const RunResult part = runClosedLoop(sc, ref, false, {}, [&asked](const MetricsAccumulator& m) {
    ++asked;
    return m.samples() >= 1000;
  });
  EXPECT_FALSE(whole.stopped);
  EXPECT_TRUE(part.stopped);
  EXPECT_EQ(asked, 4);  // asked every kStopCheckEvery (256) periods: after 256, 512, 768, 1024 samples
  for (int a = 0; a < AXIS_COUNT; ++a) {
    EXPECT_GT(part.metrics[a].itae, 0.0) << a;
    EXPECT_LE(part.metrics[a].itae, whole.metrics[a].itae) << a;  // a lower bound of the whole run's
  }
}
