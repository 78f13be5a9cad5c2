// Small helpers that turn a bad parameter into one readable line: name, value and allowed range.
#pragma once

#include <string>

namespace sowing_robot {
namespace core {

/// v with up to 10 significant digits, as error texts print it.
std::string formatNumber(double v);
/// " unit", or "" for no unit.
std::string withUnit(const std::string& unit);
/// "" if lo <= value <= hi and finite, else "name = value is outside [lo, hi] unit".
std::string checkRange(const std::string& name, double value, double lo, double hi, const std::string& unit = "");
/// "" if value > 0 and finite, else a message naming it.
std::string checkPositive(const std::string& name, double value, const std::string& unit = "");
/// "" if value >= 0 and finite, else a message naming it.
std::string checkNonNegative(const std::string& name, double value, const std::string& unit = "");
/// "" if lo < hi (both finite), else a message naming both.
std::string checkOrdered(const std::string& lo_name, double lo, const std::string& hi_name, double hi);
/// Returns the first non-empty message of the list, or "".
std::string firstError(std::initializer_list<std::string> messages);

}  // namespace core
}  // namespace sowing_robot
