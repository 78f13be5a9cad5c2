// Tracking performance indices of Tables 5.5 and 5.6, computed by this code in-process, in the
// metrics node and in analyze_bag (through the Python module sowing_robot.core; README lists them).
#pragma once

#include <array>
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

/// Accumulates errors sample by sample; integrals use the trapezoidal rule on the sample times.
class MetricsAccumulator {
 public:
  /// keep_samples: store the series for the time-domain figures (allocates; off in the PSO loop).
  explicit MetricsAccumulator(bool keep_samples = true) : keep_(keep_samples) {}
  void reserve(std::size_t n);
  void reset();
  /// One sample at time t [s] of the world-frame errors (x, y [m]; theta [rad]). A sample with a
  /// non-finite value is refused (returns false, counted by rejected()) so that one bad message cannot
  /// turn every integral into NaN; a diverged run is the caller's to report (runClosedLoop: +inf).
  bool add(double t, double ex, double ey, double etheta);
  /// Integrals so far and, when samples are kept, the time-domain figures.
  std::array<AxisMetrics, AXIS_COUNT> result() const;
  std::size_t samples() const { return count_; }
  std::size_t rejected() const { return rejected_; }

 private:
  bool keep_;
  std::size_t count_ = 0, rejected_ = 0;
  double last_t_ = 0.0;
  std::array<double, AXIS_COUNT> last_e_{};
  std::array<AxisMetrics, AXIS_COUNT> acc_{};
  std::vector<double> t_;
  std::array<std::vector<double>, AXIS_COUNT> e_;
};

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
