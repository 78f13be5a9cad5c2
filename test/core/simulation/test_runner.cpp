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

namespace {
bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Everything a RunResult and a RunTally hold, bit for bit.
void expectSameRun(const RunResult& pair, const RunTally& pair_tally, const RunResult& alone,
                   const RunTally& alone_tally, const char* what) {
  for (int i = 0; i < STATE_SIZE; ++i) EXPECT_TRUE(sameBits(pair.final_state[i], alone.final_state[i])) << what << i;
  for (int a = 0; a < AXIS_COUNT; ++a) {
    const AxisMetrics &p = pair.metrics[a], &q = alone.metrics[a];
    for (auto [x, y] : {std::pair{p.ise, q.ise},
                        {p.itse, q.itse},
                        {p.iae, q.iae},
                        {p.itae, q.itae},
                        {p.rise_time, q.rise_time},
                        {p.settling_time, q.settling_time},
                        {p.overshoot, q.overshoot}})
      EXPECT_TRUE(sameBits(x, y) || (std::isnan(x) && std::isnan(y))) << what << " axis " << a << ": " << x << " " << y;
  }
  EXPECT_EQ(pair.diverged, alone.diverged) << what;
  EXPECT_EQ(pair.periods, alone.periods) << what;
  EXPECT_EQ(pair.saturated_steps, alone.saturated_steps) << what;
  for (auto [x, y] : {std::pair{pair_tally.effort, alone_tally.effort},
                      {pair_tally.chattering, alone_tally.chattering},
                      {pair_tally.worst_cross_track, alone_tally.worst_cross_track},
                      {pair_tally.last_cross_track, alone_tally.last_cross_track}})
    EXPECT_TRUE(sameBits(x, y) || (std::isinf(x) && std::isinf(y))) << what;
  EXPECT_EQ(*pair_tally.series, *alone_tally.series) << what;
}

Scenario noisyLine(double mass_scale, std::uint64_t seed, double phase) {
  Scenario sc;
  sc.duration = 6.0;
  sc.disturbance.sinusoidal = true;
  sc.disturbance.amplitude = 1.5;
  sc.disturbance.noise_std = 0.3;
  sc.disturbance.seed = seed;
  sc.disturbance.mass_scale = mass_scale;
  sc.disturbance.inertia_scale = 2.0 - mass_scale;
  sc.disturbance_phase = phase;
  sc.start = {-1.0, 0.2 * mass_scale, 0.3 - 0.2 * mass_scale};
  return sc;
}

// runClosedLoopPair against the two runs alone: for each pair of controllers, for two runs of another
// length (one after the other), and for a run that diverges beside one that does not (the other goes on
// alone from there).
void expectPairIsTheRunsAlone(Scenario a, Scenario b, const char* what) {
  std::vector<double> series[4];
  RunTally tallies[4];
  for (int i = 0; i < 4; ++i) {
    tallies[i].dt = 0.001;
    tallies[i].settle_time = 2.0;
    tallies[i].series_every = 250;
    tallies[i].series = &series[i];
  }
  LineReference ra, rb, r;
  const std::array<RunResult, 2> pair = runClosedLoopPair(a, ra, tallies[0], b, rb, tallies[1], true);
  const RunResult alone_a = runClosedLoop(a, r, true, tallies[2]);
  const RunResult alone_b = runClosedLoop(b, r, true, tallies[3]);
  expectSameRun(pair[0], tallies[0], alone_a, tallies[2], what);
  expectSameRun(pair[1], tallies[1], alone_b, tallies[3], what);
}
}  // namespace

TEST(Runner, TwoRunsInLockstepAreTheRunsAlone) {
  const std::pair<OuterKind, InnerKind> pairs[] = {{OuterKind::kanayama, InnerKind::sliding_mode},
                                                   {OuterKind::rpp, InnerKind::pid},
                                                   {OuterKind::pure_pursuit, InnerKind::sliding_mode}};
  for (auto [outer, inner] : pairs) {
    Scenario a = noisyLine(1.3, 5, 0.4), b = noisyLine(0.8, 9, 2.0);
    a.outer = b.outer = outer;
    a.inner = b.inner = inner;
    expectPairIsTheRunsAlone(a, b, a.controllerName().c_str());
  }
  Scenario tsmc = noisyLine(1.3, 5, 0.4);
  tsmc.sliding.adaptive = false;
  expectPairIsTheRunsAlone(noisyLine(0.8, 9, 2.0), tsmc, "atsmc beside tsmc");
  Scenario shorter = noisyLine(0.8, 9, 2.0);
  shorter.duration = 4.0;
  expectPairIsTheRunsAlone(noisyLine(1.3, 5, 0.4), shorter, "another length");
  Scenario diverging = noisyLine(1.3, 5, 0.4);
  diverging.sliding.k2 = 1e6;  // as DivergenceIsReportedNotHidden
  diverging.sliding.max_torque = 1e9;
  LineReference line;
  ASSERT_TRUE(runClosedLoop(diverging, line, false).diverged);
  expectPairIsTheRunsAlone(diverging, noisyLine(0.8, 9, 2.0), "first diverges");
  expectPairIsTheRunsAlone(noisyLine(0.8, 9, 2.0), diverging, "second diverges");
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
