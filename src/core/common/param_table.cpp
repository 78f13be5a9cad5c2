#include "sowing_robot/core/common/param_table.h"

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

namespace {
std::string number(double v) { return formatNumber(v); }
}  // namespace

bool Limits::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (lo_open ? !(v > lo) : !(v >= lo)) return false;
  return hi_open ? v < hi : v <= hi;
}

std::string Limits::text() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (!has_lo && !has_hi) return "finite";
  if (!has_hi) return std::string(lo_open ? "> " : ">= ") + number(lo);
  if (!has_lo) return std::string(hi_open ? "< " : "<= ") + number(hi);
  return std::string(lo_open ? "(" : "[") + number(lo) + ", " + number(hi) + (hi_open ? ")" : "]");
}

std::string formatValue(const ParamValue& v) {
  if (const bool* b = std::get_if<bool>(&v)) return *b ? "true" : "false";
  if (const int* i = std::get_if<int>(&v)) return std::to_string(*i);
  if (const double* d = std::get_if<double>(&v)) {
    std::string s = number(*d);
    // YAML reads "1" as an int: a double prints with a decimal point (or an exponent).
    if (std::isfinite(*d) && s.find_first_of(".e") == std::string::npos) s += ".0";
    return s;
  }
  const std::string& s = std::get<std::string>(v);
  return s.empty() ? "\"\"" : s;
}

const char* typeName(const ParamValue& v) {
  switch (v.index()) {
    case 0: return "bool";
    case 1: return "int";
    case 2: return "double";
    default: return "string";
  }
}

std::string ParamInfo::check(const ParamValue& v, const std::string& prefix) const {
  const std::string name = prefix + key;
  if (v.index() != default_value.index()) return "parameter " + name + " must be of type " + typeName(default_value);
  if (const std::string* s = std::get_if<std::string>(&v)) {
    if (choices.empty()) return "";
    std::string list;
    for (const auto& c : choices) {
      if (c == *s) return "";
      list += (list.empty() ? "" : ", ") + c;
    }
    return name + " = '" + *s + "' must be one of " + list;
  }
  if (std::holds_alternative<bool>(v)) return "";
  const double x = std::holds_alternative<int>(v) ? std::get<int>(v) : std::get<double>(v);
  if (limits.contains(x)) return "";
  const std::string shown = formatValue(v);
  const bool has_lo = std::isfinite(limits.lo), has_hi = std::isfinite(limits.hi);
  if (has_lo && !has_hi) return name + " = " + shown + " must be finite and " + limits.text() + withUnit(unit);
  if (!has_lo && !has_hi) return name + " = " + shown + " must be finite" + withUnit(unit);
  return name + " = " + shown + " is outside the allowed range " + limits.text() + withUnit(unit);
}

std::string ParamInfo::rangeAndDefault() const {
  std::string range;
  if (!choices.empty()) {
    for (const auto& c : choices) range += (range.empty() ? "" : " | ") + c;
  } else if (std::holds_alternative<int>(default_value) || std::holds_alternative<double>(default_value)) {
    range = limits.text();
  } else if (std::holds_alternative<bool>(default_value)) {
    range = "bool";
  } else {
    range = "string";
  }
  return "(" + range + ", default " + formatValue(default_value) + ")";
}

}  // namespace core
}  // namespace sowing_robot
