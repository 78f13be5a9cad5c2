// Golden metrics of edge cases, written by the C++ core and read by the Python tests
// (test/python/test_core_metrics.py), so that sowing_robot.core and analyze_bag are checked against
// numbers C++ wrote, to the last bit, and a change of the core's definitions shows up here first.
//   SOWING_WRITE_GOLDEN=1 devel/lib/sowing_robot/test_metrics_golden   rewrites the file after a deliberate change.
// Format (one record per line, doubles as C99 hex floats, %a, which Python's float.fromhex reads exactly):
//   case NAME
//   s NS T EX EY ETHETA          one sample per line: stamp [ns], t = secondsFromNanos(NS) and the errors
//   count ACCEPTED REJECTED
//   kept AXIS ise itse iae itae rise_time settling_time overshoot peak    MetricsAccumulator(true).result()
//   integrals AXIS ...           the same for MetricsAccumulator(false) (time-domain fields NaN)
//   end
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "golden_file.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/simulation/metrics.h"

using namespace sowing_robot::core;

namespace {

struct Sample {
  std::int64_t ns;
  double ex, ey, eth;
};

struct Case {
  std::string name;
  std::vector<Sample> samples;
};

constexpr std::int64_t kMs = 1000000;
const double kNan = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

double damped(double t) { return std::exp(-t) * std::cos(M_PI * t); }

/// Samples at the given stamps of e_x = fx(t - t0), e_y = fy(t - t0), e_theta = fth(t - t0), t0 the first stamp.
Case sampled(const std::string& name, const std::vector<std::int64_t>& stamps, const std::function<double(double)>& fx,
             const std::function<double(double)>& fy, const std::function<double(double)>& fth) {
  Case c{name, {}};
  for (const auto ns : stamps) {
    const double t = secondsFromNanos(ns) - secondsFromNanos(stamps.front());
    c.samples.push_back({ns, fx(t), fy(t), fth(t)});
  }
  return c;
}

std::vector<std::int64_t> every(std::int64_t from_ns, std::int64_t to_ns, std::int64_t step_ns) {
  std::vector<std::int64_t> v;
  for (std::int64_t ns = from_ns; ns <= to_ns; ns += step_ns) v.push_back(ns);
  return v;
}

std::vector<Case> cases() {
  std::vector<Case> c;
  const auto exp_ = [](double t) { return std::exp(-t); };
  const auto minus2exp = [](double t) { return -2.0 * std::exp(-t); };
  c.push_back({"one_sample", {{0, 0.5, -0.25, 0.125}}});
  c.push_back({"two_samples", {{0, 0.5, -0.25, 0.125}, {kMs, 0.25, 0.5, -0.125}}});
  // peak at t = 0: the error decays from its first sample (the line start); theta crosses zero
  c.push_back(sampled("peak_at_t0", every(0, 3000 * kMs, kMs), exp_, minus2exp, damped));
  // uneven stamps: steps of 1, 2, 0.5, 6.5 ms, ... and one of 1 ns
  {
    std::vector<std::int64_t> st = {0, kMs, 3 * kMs, 3 * kMs + kMs / 2, 10 * kMs, 10 * kMs + 1, 25 * kMs};
    for (std::int64_t k = 1; k <= 200; ++k) st.push_back(25 * kMs + k * k * 75000);
    c.push_back(sampled("uneven_stamps", st, exp_, minus2exp, damped));
  }
  // a gap: 1 ms samples, 60 ms missing (what a recorder that dropped messages leaves), then 1 ms again
  {
    auto st = every(0, 199 * kMs, kMs);
    const auto after = every(260 * kMs, 3000 * kMs, kMs);
    st.insert(st.end(), after.begin(), after.end());
    c.push_back(sampled("gap", st, exp_, minus2exp, damped));
  }
  // non-finite samples: refused by the accumulator, the integral bridges them
  {
    Case n = sampled("nan_sample", every(0, 100 * kMs, kMs), exp_, minus2exp, damped);
    n.samples[37].ey = kNan;
    n.samples[50].eth = kInf;
    n.samples[0].ex = kNan;  // the first sample too: the run then starts at the second
    c.push_back(n);
  }
  // wall-clock stamps (a realtime run): large seconds, toSec's rounding matters
  c.push_back(sampled("wall_clock_stamps",
                      every(1700000000LL * 1000000000LL + 123 * kMs, 1700000000LL * 1000000000LL + 1123 * kMs, kMs),
                      exp_, minus2exp, damped));
  c.push_back(sampled(
      "zero_error", every(0, 50 * kMs, kMs), [](double) { return 0.0; }, [](double) { return 0.0; },
      [](double) { return 0.0; }));
  // peak at the end: never rises, never settles inside the run
  c.push_back(sampled(
      "peak_at_end", every(0, 500 * kMs, kMs), [](double t) { return 1.0 - std::exp(-t); }, [](double t) { return -t; },
      [](double t) { return t * t; }));
  // the negative peak with an overshoot of the time-domain definitions (README)
  c.push_back({"negative_peak_overshoot",
               {{0, 0.5, 0.5, 0.5},
                {1000 * kMs, -2.0, -2.0, 2.0},
                {2000 * kMs, -1.0, -1.0, 1.0},
                {3000 * kMs, 0.1, 0.1, -0.1},
                {4000 * kMs, 0.05, 0.05, -0.05},
                {5000 * kMs, -0.01, -0.01, 0.01}}});
  return c;
}

std::string hex(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

void writeResult(std::ostringstream& out, const char* kind, const std::array<AxisMetrics, AXIS_COUNT>& r) {
  const char* axes[] = {"x", "y", "theta"};
  for (int a = 0; a < AXIS_COUNT; ++a) {
    const AxisMetrics& m = r[a];
    out << kind << ' ' << axes[a];
    for (double v : {m.ise, m.itse, m.iae, m.itae, m.rise_time, m.settling_time, m.overshoot, m.peak})
      out << ' ' << hex(v);
    out << '\n';
  }
}

std::string golden() {
  std::ostringstream out;
  out << "# Written by test/python/metrics_golden.cpp (the C++ core); read by test/python/test_core_metrics.py.\n"
         "# SOWING_WRITE_GOLDEN=1 devel/lib/sowing_robot/test_metrics_golden rewrites it.\n";
  for (const auto& c : cases()) {
    MetricsAccumulator kept(true), integrals(false);
    out << "case " << c.name << '\n';
    for (const auto& s : c.samples) {
      const double t = secondsFromNanos(s.ns);
      out << "s " << s.ns << ' ' << hex(t) << ' ' << hex(s.ex) << ' ' << hex(s.ey) << ' ' << hex(s.eth) << '\n';
      kept.add(t, s.ex, s.ey, s.eth);
      integrals.add(t, s.ex, s.ey, s.eth);
    }
    out << "count " << kept.samples() << ' ' << kept.rejected() << '\n';
    writeResult(out, "kept", kept.result());
    writeResult(out, "integrals", integrals.result());
    out << "end\n";
  }
  return out.str();
}

}  // namespace

TEST(MetricsGolden, FileMatchesTheCore) { expectGoldenFile(golden(), SOWING_GOLDEN_PATH, "metrics"); }
