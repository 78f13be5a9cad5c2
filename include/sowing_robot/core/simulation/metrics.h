// Tracking performance indices of Tables 5.5 and 5.6, computed by this code in-process, in the
// metrics node and in analyze_bag (through the Python module sowing_robot.core; README lists them).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace sowing_robot {
namespace core {

enum Axis { AXIS_X = 0, AXIS_Y, AXIS_THETA, AXIS_COUNT };

/// Indices for one error signal e(t).
struct AxisMetrics {
  double ise = 0.0;   ///< integral of e^2
  double itse = 0.0;  ///< integral of t e^2
  double iae = 0.0;   ///< integral of |e|
  double itae = 0.0;  ///< integral of t |e|
  /// Time-domain figures of the error's decay, normalised by its peak E = max |e| (reached at t_p):
  double rise_time = 0.0;      ///< from |e| <= 0.9 E to |e| <= 0.1 E, first times after t_p [s]; NaN if never
  double settling_time = 0.0;  ///< last time |e| > 0.02 E, from t = 0 [s]
  double overshoot = 0.0;      ///< largest error of opposite sign after the first zero crossing / E [%]
  double peak = 0.0;           ///< E
};

/// The time-domain figures of one error series, computed sample by sample in O(1) memory, with the same
/// comparisons, in the same order, as timeDomainMetrics() makes over the stored series, so both give
/// bit-identical values (test_metrics: StreamingTimeDomainEqualsTheStoredSeries). Why streaming works:
/// the peak E only grows, and every figure looks at the samples from the peak on (rise, overshoot), or
/// at the last sample above 0.02 E, which is the peak itself or a later one; so whenever a new peak
/// arrives, what was found before it is thrown away and the search starts again at the new peak.
class StreamingTimeDomain {
 public:
  void reset() { *this = StreamingTimeDomain{}; }
  void add(double t, double e) {
    const double a = std::fabs(e);
    if (n_ == 0 || a > peak_) {    // a new (first) peak: the figures start again from here
      if (n_ == 0) settling_ = t;  // no sample above 0.02 E: the first time
      peak_ = a;
      sign_ = e > 0.0 ? 1.0 : -1.0;
      have_t90_ = have_t10_ = false;
      worst_ = 0.0;
      // The thresholds, the same products as computing them at every sample, once per peak.
      at90_ = 0.9 * peak_;
      at10_ = 0.1 * peak_;
      at02_ = 0.02 * peak_;
    }
    ++n_;
    if (!have_t10_) {  // the stored search stops at the first sample <= 0.1 E after the peak
      if (!have_t90_ && a <= at90_) {
        t90_ = t;
        have_t90_ = true;
      }
      if (a <= at10_) {
        t10_ = t;
        have_t10_ = true;
      }
    }
    worst_ = std::max(worst_, -sign_ * e);
    // settling: the sample after the last one above 0.02 E (that one itself when it is the last)
    if (a > at02_) {
      settling_ = t;
      after_exceed_ = true;
    } else if (after_exceed_) {
      settling_ = t;
      after_exceed_ = false;
    }
  }
  /// rise_time, settling_time, overshoot and peak of the samples so far (integrals left untouched).
  void result(AxisMetrics& m) const;

 private:
  std::size_t n_ = 0;
  double peak_ = 0.0, sign_ = 1.0, worst_ = 0.0;  // E, the sign of the peak's error, max of -sign e
  double t90_ = 0.0, t10_ = 0.0, settling_ = 0.0;
  double at90_ = 0.0, at10_ = 0.0, at02_ = 0.0;  // 0.9 E, 0.1 E, 0.02 E
  bool have_t90_ = false, have_t10_ = false, after_exceed_ = false;
};

/// Accumulates errors sample by sample; integrals use the trapezoidal rule on the sample times. O(1)
/// memory: the time-domain figures are computed as the samples arrive (StreamingTimeDomain).
class MetricsAccumulator {
 public:
  /// keep_samples: compute the time-domain figures too (the name is historical: no sample is stored any
  /// more; off in the PSO loop, where they are NaN).
  explicit MetricsAccumulator(bool keep_samples = true) : keep_(keep_samples) {}
  /// Kept for callers that sized the sample store; nothing is stored, so it does nothing.
  void reserve(std::size_t) {}
  void reset();
  /// One sample at time t [s] of the world-frame errors (x, y [m]; theta [rad]). A sample with a
  /// non-finite value is refused (returns false, counted by rejected()) so that one bad message cannot
  /// turn every integral into NaN; a diverged run is the caller's to report (runClosedLoop: +inf).
  /// Inline, and axis by axis in scalars: it runs every period of runClosedLoop, where the loop over the
  /// axes was vectorised into 16-byte stores and loads of the same terms (store-forwarding stalls).
  bool add(double t, double ex, double ey, double etheta) {
    // x - x is +0 for a finite x and NaN for inf or NaN: one test for the four (allFinite's result).
    if (!((t - t) + (ex - ex) + (ey - ey) + (etheta - etheta) == 0.0)) {
      ++rejected_;
      return false;
    }
    // Trapezoids: each integral adds 0.5 h (f(t_last) + f(t)), f = e^2, t e^2, |e|, t |e|. f(t) is kept
    // for the next sample's f(t_last): the same products of the same operands as computing it again then.
    const bool first = count_ == 0;
    const double h = t - last_t_;
    addAxis(AXIS_X, first, h, t, ex);
    addAxis(AXIS_Y, first, h, t, ey);
    addAxis(AXIS_THETA, first, h, t, etheta);
    last_t_ = t;
    ++count_;
    if (keep_) {
      time_domain_[AXIS_X].add(t, ex);
      time_domain_[AXIS_Y].add(t, ey);
      time_domain_[AXIS_THETA].add(t, etheta);
    }
    return true;
  }
  /// Integrals so far and, when samples are kept, the time-domain figures.
  std::array<AxisMetrics, AXIS_COUNT> result() const;
  std::size_t samples() const { return count_; }
  std::size_t rejected() const { return rejected_; }

 private:
  bool keep_;
  std::size_t count_ = 0, rejected_ = 0;
  double last_t_ = 0.0;
  struct Terms {
    double sq, t_sq, abs, t_abs;  // e^2, t e^2, |e|, t |e| of one sample
  };
  std::array<Terms, AXIS_COUNT> last_terms_{};  // of the last sample

  void addAxis(int a, bool first, double h, double t, double e) {
    const double abs = std::fabs(e);
    const Terms c{e * e, t * e * e, abs, t * abs};
    Terms& p = last_terms_[a];
    if (!first) {
      AxisMetrics& m = acc_[a];
      m.ise += 0.5 * h * (p.sq + c.sq);
      m.itse += 0.5 * h * (p.t_sq + c.t_sq);
      m.iae += 0.5 * h * (p.abs + c.abs);
      m.itae += 0.5 * h * (p.t_abs + c.t_abs);
    }
    p = c;
  }
  std::array<AxisMetrics, AXIS_COUNT> acc_{};
  std::array<StreamingTimeDomain, AXIS_COUNT> time_domain_{};
};

/// One figure of AxisMetrics as everything that names it does: the rows of metricsTable, the keys of the
/// metrics YAML (run_monitor's metrics_output, run_scenario --yaml, analyze_bag --yaml), the Python metrics
/// dicts (sowing_robot.core) and the benchmark's runs.csv columns NAME_AXIS (evaluation/run_metrics.h).
struct AxisFigure {
  const char* name;     ///< YAML and dict key
  const char* label;    ///< metricsTable's row (followed by " [unit]" where the unit is the same on every axis)
  const char* unit;     ///< E stands for the error's unit: m on x and y, rad on theta (axisUnit)
  const char* meaning;  ///< one line
  double AxisMetrics::*member;
};
/// The figures of the table, the YAML and runs.csv, in their order. AxisMetrics::peak is not one of them (the
/// Python dicts add it).
const std::vector<AxisFigure>& axisFigures();
/// "x", "y", "theta": the YAML's and dicts' axis keys, runs.csv's column suffix.
const char* axisName(int axis);
/// `figure`'s unit on `axis` (its E replaced by m or rad).
std::string axisUnit(const AxisFigure& figure, int axis);

/// Time-domain figures of one series (the definitions above).
void timeDomainMetrics(const std::vector<double>& t, const std::vector<double>& e, AxisMetrics& m);

/// Markdown table with one column block per run: rows ISE..overshoot, columns x, y, theta.
std::string metricsTable(const std::vector<std::string>& names,
                         const std::vector<std::array<AxisMetrics, AXIS_COUNT>>& runs);

/// Writes metrics as YAML at full precision: {label: {x: {ise: .., ...}, y: {...}, theta: {...}}}.
/// The format run_monitor (metrics_output), run_scenario --yaml and analyze_bag --yaml share.
bool writeMetricsYaml(const std::string& path, const std::string& label, const std::array<AxisMetrics, AXIS_COUNT>& m);

}  // namespace core
}  // namespace sowing_robot
