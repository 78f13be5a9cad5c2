// Performance indices (Table 5.5) and time-domain figures (Table 5.6) on signals with known answers.
#include <gtest/gtest.h>

#include <cmath>

#include "sowing_robot/core/metrics.h"

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
