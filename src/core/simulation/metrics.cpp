#include "sowing_robot/core/simulation/metrics.h"

#include "sowing_robot/core/common/types.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <limits>

namespace sowing_robot {
namespace core {

void StreamingTimeDomain::result(AxisMetrics& m) const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  m.rise_time = m.settling_time = nan;
  m.overshoot = m.peak = 0.0;
  if (n_ == 0) return;
  m.peak = peak_;
  if (!(peak_ > 0.0)) {
    m.rise_time = m.settling_time = 0.0;
    return;
  }
  m.rise_time = have_t90_ && have_t10_ ? t10_ - t90_ : nan;
  m.settling_time = settling_;
  m.overshoot = 100.0 * worst_ / peak_;
}

void MetricsAccumulator::reset() {
  count_ = rejected_ = 0;
  acc_ = {};
  for (auto& d : time_domain_) d.reset();
}

std::array<AxisMetrics, AXIS_COUNT> MetricsAccumulator::result() const {
  auto r = acc_;
  if (keep_ && count_ > 0) {
    for (int a = 0; a < AXIS_COUNT; ++a) time_domain_[a].result(r[a]);
  } else {
    const double nan = std::numeric_limits<double>::quiet_NaN();  // not computed, not zero
    for (auto& m : r) m.rise_time = m.settling_time = m.overshoot = m.peak = nan;
  }
  return r;
}

// The definition over a stored series (the reference StreamingTimeDomain is tested against; the Python
// module's time_domain_metrics).
void timeDomainMetrics(const std::vector<double>& t, const std::vector<double>& e, AxisMetrics& m) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  m.rise_time = m.settling_time = nan;
  m.overshoot = m.peak = 0.0;
  const std::size_t n = e.size();
  if (n == 0) return;
  std::size_t ip = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (std::fabs(e[i]) > std::fabs(e[ip])) ip = i;
  const double E = std::fabs(e[ip]);
  m.peak = E;
  if (!(E > 0.0)) {
    m.rise_time = m.settling_time = 0.0;
    return;
  }
  double t90 = nan, t10 = nan;
  for (std::size_t i = ip; i < n; ++i) {
    if (std::isnan(t90) && std::fabs(e[i]) <= 0.9 * E) t90 = t[i];
    if (std::fabs(e[i]) <= 0.1 * E) {
      t10 = t[i];
      break;
    }
  }
  m.rise_time = std::isnan(t90) || std::isnan(t10) ? nan : t10 - t90;
  m.settling_time = t.front();
  for (std::size_t i = n; i-- > 0;)
    if (std::fabs(e[i]) > 0.02 * E) {
      m.settling_time = i + 1 < n ? t[i + 1] : t[i];
      break;
    }
  const double sign = e[ip] > 0.0 ? 1.0 : -1.0;
  double worst = 0.0;
  for (std::size_t i = ip; i < n; ++i) worst = std::max(worst, -sign * e[i]);
  m.overshoot = 100.0 * worst / E;
}

const std::vector<AxisFigure>& axisFigures() {
  static const std::vector<AxisFigure> figures{
      {"ise", "ISE", "E²·s", "integral of e^2 (trapezoids on the sample times)", &AxisMetrics::ise},
      {"itse", "ITSE", "E²·s²", "integral of t e^2", &AxisMetrics::itse},
      {"iae", "IAE", "E·s", "integral of |e|", &AxisMetrics::iae},
      {"itae", "ITAE", "E·s²", "integral of t |e|", &AxisMetrics::itae},
      {"rise_time", "rise time", "s", "from |e| <= 0.9 E to |e| <= 0.1 E after the peak E = max |e| (NaN if never)",
       &AxisMetrics::rise_time},
      {"settling_time", "settling time", "s", "last time |e| > 0.02 E, from t = 0", &AxisMetrics::settling_time},
      {"overshoot", "overshoot", "%", "largest error of opposite sign after the first zero crossing, over E",
       &AxisMetrics::overshoot}};
  return figures;
}

const char* axisName(int axis) {
  static const char* const names[AXIS_COUNT] = {"x", "y", "theta"};
  return names[axis];
}

std::string axisUnit(const AxisFigure& figure, int axis) {
  std::string unit;
  for (const char* c = figure.unit; *c != '\0'; ++c)
    unit += *c == 'E' ? std::string(axis == AXIS_THETA ? "rad" : "m") : std::string(1, *c);
  return unit;
}

std::string metricsTable(const std::vector<std::string>& names,
                         const std::vector<std::array<AxisMetrics, AXIS_COUNT>>& runs) {
  std::string s = "| metric | axis |";
  for (const auto& n : names) s += " " + n + " |";
  s += "\n|---|---|";
  for (std::size_t i = 0; i < names.size(); ++i) s += "---:|";
  s += "\n";
  char buf[64];
  for (const AxisFigure& f : axisFigures()) {
    // The unit in the label where the axes share it (times, %); the integrals' differ by axis.
    const std::string label = std::string(f.label) + (std::strchr(f.unit, 'E') ? "" : std::string(" [") + f.unit + "]");
    for (int a = 0; a < AXIS_COUNT; ++a) {
      s += "| " + label + " | " + axisName(a) + " |";
      for (const auto& r : runs) {
        std::snprintf(buf, sizeof buf, " %.4g |", r[a].*f.member);
        s += buf;
      }
      s += "\n";
    }
  }
  return s;
}

bool writeMetricsYaml(const std::string& path, const std::string& label, const std::array<AxisMetrics, AXIS_COUNT>& m) {
  std::ofstream f(path);
  if (!f) return false;
  f << std::setprecision(17) << label << ":\n";
  for (int a = 0; a < AXIS_COUNT; ++a) {
    f << "  " << axisName(a) << ": {";
    const char* sep = "";
    for (const AxisFigure& fig : axisFigures()) {
      f << sep << fig.name << ": " << m[a].*fig.member;
      sep = ", ";
    }
    f << "}\n";
  }
  return static_cast<bool>(f);
}

}  // namespace core
}  // namespace sowing_robot
