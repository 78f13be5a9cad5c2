// Performance indices (Table 5.5) and time-domain figures (Table 5.6) on signals with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <utility>
#include <vector>

#include "sowing_robot/core/simulation/metrics.h"

using namespace sowing_robot::core;

TEST(Metrics, IntegralsOfAConstantError) {
  MetricsAccumulator m;
  for (int i = 0; i <= 1000; ++i) m.add(i * 0.01, 2.0, -1.0, 0.5);
  const auto r = m.result();
  EXPECT_NEAR(r[AXIS_X].ise, 4.0 * 10, 1e-9);
  EXPECT_NEAR(r[AXIS_X].itse, 4.0 * 50, 1e-9);
  EXPECT_NEAR(r[AXIS_Y].iae, 10.0, 1e-9);
  EXPECT_NEAR(r[AXIS_Y].itae, 50.0, 1e-9);
  EXPECT_NEAR(r[AXIS_THETA].ise, 0.25 * 10, 1e-9);
}

TEST(Metrics, IntegralsOfAnExponentialDecay) {
  MetricsAccumulator m;
  const double h = 1e-4;
  for (int i = 0; i <= 200000; ++i) {
    const double t = i * h;
    m.add(t, std::exp(-t), 0, 0);
  }
  const auto r = m.result();
  EXPECT_NEAR(r[AXIS_X].iae, 1.0, 1e-6);    // int e^-t
  EXPECT_NEAR(r[AXIS_X].itae, 1.0, 1e-6);   // int t e^-t
  EXPECT_NEAR(r[AXIS_X].ise, 0.5, 1e-6);    // int e^-2t
  EXPECT_NEAR(r[AXIS_X].itse, 0.25, 1e-6);  // int t e^-2t
  EXPECT_NEAR(r[AXIS_X].rise_time, std::log(9.0), 1e-3);
  EXPECT_NEAR(r[AXIS_X].settling_time, std::log(50.0), 1e-3);
  EXPECT_EQ(r[AXIS_X].overshoot, 0.0);
}

TEST(Metrics, OvershootOfAnUnderdampedError) {
  // e = e^-t cos(2t): after the first zero the error swings to the other side.
  std::vector<double> t, e;
  for (int i = 0; i <= 20000; ++i) {
    t.push_back(i * 1e-3);
    e.push_back(std::exp(-t.back()) * std::cos(2 * t.back()));
  }
  AxisMetrics m;
  timeDomainMetrics(t, e, m);
  // first negative peak at tan(2t) = -1/2 -> t = (pi - atan(0.5))/2
  const double tp = (M_PI - std::atan(0.5)) / 2;
  EXPECT_NEAR(m.overshoot, 100 * std::exp(-tp) * std::fabs(std::cos(2 * tp)), 0.05);
  EXPECT_EQ(m.peak, 1.0);
}

TEST(Metrics, PeakLaterThanStartIsTheReference) {
  // theta error starts at 0, grows, then decays: normalised by its peak.
  std::vector<double> t, e;
  for (int i = 0; i <= 10000; ++i) {
    t.push_back(i * 1e-3);
    e.push_back(t.back() * std::exp(-t.back()));  // peak 1/e at t = 1
  }
  AxisMetrics m;
  timeDomainMetrics(t, e, m);
  EXPECT_NEAR(m.peak, std::exp(-1.0), 1e-9);
  EXPECT_GT(m.rise_time, 0.0);
  EXPECT_GT(m.settling_time, 5.0);
}

TEST(Metrics, TableHasOneColumnPerRun) {
  MetricsAccumulator a, b;
  a.add(0, 1, 1, 1);
  a.add(1, 1, 1, 1);
  b.add(0, 2, 2, 2);
  b.add(1, 2, 2, 2);
  const std::string s = metricsTable({"A", "B"}, {a.result(), b.result()});
  EXPECT_NE(s.find("| metric | axis | A | B |"), std::string::npos);
  EXPECT_NE(s.find("| ISE | x | 1 | 4 |"), std::string::npos);
}

TEST(Metrics, WithoutSamplesTheTimeDomainFiguresAreNaNNotZero) {
  MetricsAccumulator m(false);
  for (int i = 0; i <= 100; ++i) m.add(i * 0.01, 1.0, 1.0, 1.0);
  const auto r = m.result();
  EXPECT_NEAR(r[AXIS_X].ise, 1.0, 1e-12);  // the integrals are still there
  EXPECT_TRUE(std::isnan(r[AXIS_X].settling_time));
  EXPECT_TRUE(std::isnan(r[AXIS_Y].overshoot));
}

namespace {
bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The accumulator's streaming figures against timeDomainMetrics() over the stored series, to the bit.
void expectStreamingEqualsStored(const std::vector<double>& t, const std::vector<double>& e, const char* what) {
  MetricsAccumulator acc(true);
  for (std::size_t i = 0; i < t.size(); ++i) acc.add(t[i], e[i], -e[i], 0.5 * e[i]);
  AxisMetrics stored, stored_half;
  std::vector<double> neg(e), half(e);
  for (auto& x : neg) x = -x;
  for (auto& x : half) x *= 0.5;
  timeDomainMetrics(t, e, stored);
  timeDomainMetrics(t, half, stored_half);
  const auto r = acc.result();
  AxisMetrics stored_neg;
  timeDomainMetrics(t, neg, stored_neg);
  const AxisMetrics* want[AXIS_COUNT] = {&stored, &stored_neg, &stored_half};
  for (int a = 0; a < AXIS_COUNT; ++a) {
    EXPECT_TRUE(sameBits(r[a].rise_time, want[a]->rise_time))
        << what << " axis " << a << " rise " << r[a].rise_time << " vs " << want[a]->rise_time;
    EXPECT_TRUE(sameBits(r[a].settling_time, want[a]->settling_time))
        << what << " axis " << a << " settling " << r[a].settling_time << " vs " << want[a]->settling_time;
    EXPECT_TRUE(sameBits(r[a].overshoot, want[a]->overshoot))
        << what << " axis " << a << " overshoot " << r[a].overshoot << " vs " << want[a]->overshoot;
    EXPECT_TRUE(sameBits(r[a].peak, want[a]->peak)) << what << " axis " << a;
  }
}
}  // namespace

// The accumulator keeps no samples: its rise/settling/overshoot are computed as the samples arrive.
// They must be the stored-series definition's exactly, whatever the shape: later and repeated peaks
// (each new peak restarts the search), a last sample above 2 %, no 10 % crossing, all zeros.
TEST(Metrics, StreamingTimeDomainEqualsTheStoredSeries) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<std::pair<const char*, std::function<double(double, int)>>> shapes = {
      {"underdamped", [](double t, int) { return std::exp(-t) * std::cos(2 * t); }},
      {"late peak", [](double t, int) { return t * std::exp(-t); }},
      {"growing", [](double t, int) { return t * std::sin(3 * t); }},
      {"repeated peaks", [](double t, int) { return std::round(std::cos(t)); }},
      {"constant", [](double, int) { return 0.25; }},
      {"zeros", [](double, int) { return 0.0; }},
      {"spike at the end", [](double, int i) { return i == 2000 ? 3.0 : 0.01; }},
      {"noise", [&](double t, int) { return std::exp(-0.3 * t) * u(rng); }},
      {"step down", [](double t, int) { return t < 1.0 ? -1.0 : (t < 2.0 ? 0.5 : 0.005); }},
  };
  for (const auto& [name, f] : shapes) {
    std::vector<double> t, e;
    for (int i = 0; i <= 2000; ++i) {
      t.push_back(i * 5e-3);
      e.push_back(f(t.back(), i));
    }
    expectStreamingEqualsStored(t, e, name);
    std::vector<double> one_t(1, t[0]), one_e(1, e[0]);
    expectStreamingEqualsStored(one_t, one_e, name);
  }
}

TEST(Metrics, AccumulatorMemoryDoesNotGrowWithTheRun) {
  // O(1) in the run's length: a plain value type, no sample store behind it.
  static_assert(sizeof(MetricsAccumulator) < 1024, "the accumulator must not hold the series");
  MetricsAccumulator m(true);
  for (int i = 0; i <= 100000; ++i) m.add(i * 1e-3, std::exp(-i * 1e-3), 0.0, 0.0);
  EXPECT_EQ(m.samples(), 100001u);
  EXPECT_GT(m.result()[AXIS_X].settling_time, 0.0);
}
