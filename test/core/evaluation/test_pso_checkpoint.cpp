// The PSO as ask/tell and its checkpoints: PsoSearch driven by hand is psoMinimize; its
// text state round-trips exactly; stopping after any iteration K, writing the state and resuming from it
// gives the uninterrupted result bit for bit (the PSO alone and the tuner); damaged, truncated or foreign
// checkpoint files are refused with one line.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sowing_robot/core/evaluation/checkpoint.h"
#include "sowing_robot/core/evaluation/pso.h"
#include "sowing_robot/core/evaluation/tuning.h"

using namespace sowing_robot::core;

namespace {

double rastrigin(const std::vector<double>& x) {
  double c = 10.0 * static_cast<double>(x.size());
  for (double v : x) c += v * v - 10.0 * std::cos(2.0 * M_PI * v);
  return c;
}

PsoParams params(int iterations = 12) {
  PsoParams p;
  p.lower.assign(3, -5.12);
  p.upper.assign(3, 5.12);
  p.particles = 7;
  p.iterations = iterations;
  p.seed = 11;
  p.threads = 2;
  p.max_velocity_fraction = 0.2;
  return p;
}

std::vector<double> costs(const PsoSearch& s) {
  std::vector<double> c;
  for (const auto& x : s.positions()) c.push_back(rastrigin(x));
  return c;
}

void expectSameBits(const PsoResult& a, const PsoResult& b) {
  ASSERT_EQ(a.best_position.size(), b.best_position.size());
  EXPECT_EQ(0, std::memcmp(&a.best_cost, &b.best_cost, sizeof(double)));
  EXPECT_EQ(0, std::memcmp(a.best_position.data(), b.best_position.data(), a.best_position.size() * sizeof(double)));
  ASSERT_EQ(a.best_cost_per_iteration.size(), b.best_cost_per_iteration.size());
  EXPECT_EQ(0, std::memcmp(a.best_cost_per_iteration.data(), b.best_cost_per_iteration.data(),
                           a.best_cost_per_iteration.size() * sizeof(double)));
  EXPECT_EQ(a.evaluations, b.evaluations);
}

std::string tempPath(const char* name) { return "/tmp/test_pso_checkpoint_" + std::to_string(::getpid()) + name; }

}  // namespace

TEST(PsoSearch, DrivenByHandIsPsoMinimize) {
  const PsoResult threaded =
      psoMinimize(params(), PsoFitness([](const std::vector<double>& x, int) { return rastrigin(x); }));
  PsoSearch s(params());
  while (!s.finished()) s.tell(costs(s));
  expectSameBits(threaded, s.result());
  EXPECT_THROW(s.tell(costs(s)), std::logic_error);
}

TEST(PsoSearch, TextRoundTripsExactly) {
  PsoSearch s(params());
  for (int k = 0; k < 5; ++k) s.tell(costs(s));
  const std::string text = s.toText();
  const PsoSearch back = PsoSearch::fromText(params(), text);
  EXPECT_EQ(text, back.toText());
  EXPECT_EQ(back.iteration(), 5);
}

TEST(PsoSearch, ResumedAfterEveryIterationEqualsUninterrupted) {
  PsoSearch whole(params());
  while (!whole.finished()) whole.tell(costs(whole));
  for (int k = 0; k <= params().iterations; ++k) {
    PsoSearch first(params());
    for (int i = 0; i <= k; ++i) first.tell(costs(first));
    const std::string saved = first.toText();  // the process "dies" here
    PsoSearch resumed = PsoSearch::fromText(params(), saved);
    while (!resumed.finished()) resumed.tell(costs(resumed));
    SCOPED_TRACE("stopped after iteration " + std::to_string(k));
    expectSameBits(whole.result(), resumed.result());
  }
}

TEST(PsoSearch, RefusesTheStateOfOtherParametersOrADamagedOne) {
  PsoSearch s(params());
  s.tell(costs(s));
  const std::string text = s.toText();
  PsoParams other = params();
  other.seed = 12;
  try {
    PsoSearch::fromText(other, text);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("other PSO parameters"), std::string::npos) << e.what();
  }
  other = params(13);
  EXPECT_THROW(PsoSearch::fromText(other, text), std::invalid_argument);
  EXPECT_THROW(PsoSearch::fromText(params(), text.substr(0, text.size() / 2)), std::invalid_argument);
  std::string bad = text;
  bad.replace(bad.find("particle 3"), 10, "particle 4");
  EXPECT_THROW(PsoSearch::fromText(params(), bad), std::invalid_argument);
  EXPECT_THROW(PsoSearch::fromText(params(), "pso_state 2\n"), std::invalid_argument);
}

TEST(TuningSession, ResumedAfterIterationKEqualsTuneGains) {
  Scenario sc;
  sc.duration = 2.0;
  sc.control_period_ns = 2000000;
  sc.disturbance.sinusoidal = true;
  sc.disturbance.amplitude = 2.75;
  sc.disturbance.mass_scale = 1.2;
  const LineReference ref(1.0, 3.0, 0.0);
  PsoParams p;
  p.particles = 5;
  p.iterations = 5;
  p.seed = 3;
  p.threads = 2;
  p.max_velocity_fraction = 0.2;
  const std::vector<GainBounds> gains = defaultGainBounds();
  const TuningResult whole = tuneGains(sc, ref, gains, TuningObjective(), p);
  for (int k : {0, 2, 4}) {
    SCOPED_TRACE("stopped after iteration " + std::to_string(k));
    TuningSession first(sc, ref, gains, TuningObjective(), p, 2);
    const TuningBatch batch = threadedTuningBatch(first.problem(), first.params());
    for (int i = 0; i <= k; ++i) first.step(batch);
    const std::string saved = first.toText();
    TuningSession resumed(sc, ref, gains, TuningObjective(), p, 1);
    resumed.restore(saved);
    EXPECT_EQ(saved, resumed.toText());
    const TuningBatch one = threadedTuningBatch(resumed.problem(), resumed.params());
    while (!resumed.finished()) resumed.step(one);
    const TuningResult r = resumed.result();
    expectSameBits(whole.pso, r.pso);
    EXPECT_EQ(whole.evaluations_cut, r.evaluations_cut);
    EXPECT_EQ(whole.simulated_s, r.simulated_s);
  }
}

TEST(CheckpointFile, RoundTripsAndRefusesDamage) {
  const std::string path = tempPath(".ckpt");
  const std::string body = "line one\nline two 0x1.8p+1\n";
  ASSERT_EQ("", writeCheckpoint(path, "tune", 42, body));
  std::string back;
  EXPECT_EQ("", readCheckpoint(path, "tune", 42, back));
  EXPECT_EQ(body, back);
  EXPECT_NE(readCheckpoint(path, "tune", 43, back).find("another setup"), std::string::npos);
  EXPECT_NE(readCheckpoint(path, "bench", 42, back).find("not a 'bench'"), std::string::npos);

  std::ifstream in(path);
  std::string all((std::istreambuf_iterator<char>(in)), {});
  auto rewrite = [&](const std::string& text) { std::ofstream(path, std::ios::trunc) << text; };
  std::string flipped = all;
  flipped[flipped.size() - 3] ^= 1;  // one bit of the body
  rewrite(flipped);
  EXPECT_NE(readCheckpoint(path, "tune", 42, back).find("checksum"), std::string::npos);
  rewrite(all.substr(0, all.size() - 4));
  EXPECT_NE(readCheckpoint(path, "tune", 42, back).find("truncated"), std::string::npos);
  std::string version = all;
  version.replace(version.find(" 1 tune"), 7, " 9 tune");
  rewrite(version);
  EXPECT_NE(readCheckpoint(path, "tune", 42, back).find("version 9"), std::string::npos);
  rewrite("hello\n");
  EXPECT_NE(readCheckpoint(path, "tune", 42, back).find("not a checkpoint"), std::string::npos);
  std::remove(path.c_str());
  EXPECT_NE(readCheckpoint(path, "tune", 42, back).find("cannot read"), std::string::npos);
  // Every error is one line.
  EXPECT_EQ(readCheckpoint(path, "tune", 42, back).find('\n'), std::string::npos);
}
