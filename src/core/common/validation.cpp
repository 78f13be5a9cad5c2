#include "sowing_robot/core/common/validation.h"

#include <cmath>
#include <sstream>

namespace sowing_robot {
namespace core {

std::string formatNumber(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string withUnit(const std::string& unit) { return unit.empty() ? "" : " " + unit; }

std::string checkRange(const std::string& name, double value, double lo, double hi, const std::string& unit) {
  if (std::isfinite(value) && value >= lo && value <= hi) return "";
  return name + " = " + formatNumber(value) + " is outside the allowed range [" + formatNumber(lo) + ", " +
         formatNumber(hi) + "]" + withUnit(unit);
}

std::string checkPositive(const std::string& name, double value, const std::string& unit) {
  if (std::isfinite(value) && value > 0.0) return "";
  return name + " = " + formatNumber(value) + " must be finite and > 0" + withUnit(unit);
}

std::string checkNonNegative(const std::string& name, double value, const std::string& unit) {
  if (std::isfinite(value) && value >= 0.0) return "";
  return name + " = " + formatNumber(value) + " must be finite and >= 0" + withUnit(unit);
}

std::string checkOrdered(const std::string& lo_name, double lo, const std::string& hi_name, double hi) {
  if (std::isfinite(lo) && std::isfinite(hi) && lo < hi) return "";
  return lo_name + " = " + formatNumber(lo) + " must be finite and below " + hi_name + " = " + formatNumber(hi);
}

std::string firstError(std::initializer_list<std::string> messages) {
  for (const auto& m : messages)
    if (!m.empty()) return m;
  return "";
}

}  // namespace core
}  // namespace sowing_robot
