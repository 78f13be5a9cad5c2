// One declaration per parameter: its key, default, allowed range, unit and one-line meaning, in one
// table per component (the idea of generate_parameter_library). Everything else follows from the table:
// the params struct's defaults (its constructor applies them), range validation and its error text, the
// ROS loader (type, unknown keys), the logged effective values, docs/parameters.md, and the checks that
// keep the .cfg files and the comments in config/*.yaml in step (test/core/settings/test_param_docs.cpp).
//
// Adding a parameter to a component: one entry in its table (the struct's table function, next to the
// struct) plus the member it sets and its use. Cross-parameter rules (min < max, p/q odd) stay in the
// struct's validate(), after checkRanges().
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace sowing_robot {
namespace core {

/// A parameter's value, as loaded (YAML bool, int, double or string).
using ParamValue = std::variant<bool, int, double, std::string>;

/// The allowed values of a number: finite, between lo and hi, each bound closed or open (an infinite
/// bound only says "finite").
struct Limits {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;

  static Limits any() { return {}; }
  static Limits positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
  static Limits nonNegative() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }
  static Limits closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Limits atLeast(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, false}; }
  /// (lo, hi]
  static Limits above(double lo, double hi) { return {lo, hi, true, false}; }
  bool contains(double v) const;
  /// "> 0", ">= 0", "[1, 100000]", "(0, 1e-3]", "finite".
  std::string text() const;
};

/// Everything said about one parameter, whatever its struct: what docs, error texts and checks need.
struct ParamInfo {
  std::string key;  ///< relative to the component's namespace, '/' between levels: "disturbance/amplitude"
  ParamValue default_value;
  Limits limits;                     ///< numbers only
  std::vector<std::string> choices;  ///< strings: the allowed values (empty: any string)
  std::string unit;                  ///< SI unit as printed ("N·m", "1/s"); empty for none
  std::string meaning;               ///< one line
  bool tunable = false;              ///< the PSO tuner may search it (a double gain of a controller)

  /// "" if `v` has this parameter's type and lies in its range (or is one of its choices), else one
  /// line: "<prefix><key> = <value> ...".
  std::string check(const ParamValue& v, const std::string& prefix = "") const;
  /// "(> 0, default 1.5)"-style summary of range and default, as docs and YAML comments print it.
  std::string rangeAndDefault() const;
};

/// The value as YAML would write it: 1.5, 3, true, atsmc.
std::string formatValue(const ParamValue& v);
/// "bool", "int", "double", "string".
const char* typeName(const ParamValue& v);

template <typename S>
struct ParamEntry {
  ParamInfo info;
  std::function<ParamValue(const S&)> get;
  std::function<void(S&, const ParamValue&)> set;  ///< the value has the entry's type (checked by the loader)
};

/// The parameters of one component, in the order they are documented and logged.
template <typename S>
class ParamTable {
 public:
  ParamTable() = default;
  explicit ParamTable(std::vector<ParamEntry<S>> entries) : entries_(std::move(entries)) {}

  const std::vector<ParamEntry<S>>& entries() const { return entries_; }
  const ParamEntry<S>* find(const std::string& key) const {
    for (const auto& e : entries_)
      if (e.info.key == key) return &e;
    return nullptr;
  }

  /// Every entry's default into s.
  void applyDefaults(S& s) const {
    for (const auto& e : entries_) e.set(s, e.info.default_value);
  }
  /// First out-of-range value as one line naming the key ("" when all are in range).
  std::string checkRanges(const S& s, const std::string& prefix = "") const {
    for (const auto& e : entries_) {
      const std::string error = e.info.check(e.get(s), prefix);
      if (!error.empty()) return error;
    }
    return "";
  }
  /// "key value, key value, ..." of the values in force (for the start-up log line).
  std::string describe(const S& s, const std::string& prefix = "") const {
    std::string out;
    for (const auto& e : entries_) {
      out += (out.empty() ? "" : ", ") + prefix + e.info.key + " " + formatValue(e.get(s));
      if (!e.info.unit.empty()) out += " " + e.info.unit;
    }
    return out;
  }
  /// Another table's entries under `prefix`, reached through `member` (a nested params struct).
  template <typename N>
  ParamTable& nest(const std::string& prefix, N S::*member, const ParamTable<N>& table) {
    for (const auto& e : table.entries()) {
      ParamEntry<S> n;
      n.info = e.info;
      n.info.key = prefix + e.info.key;
      n.get = [member, get = e.get](const S& s) { return get(s.*member); };
      n.set = [member, set = e.set](S& s, const ParamValue& v) { set(s.*member, v); };
      entries_.push_back(std::move(n));
    }
    return *this;
  }
  ParamTable& add(ParamEntry<S> e) {
    entries_.push_back(std::move(e));
    return *this;
  }

 private:
  std::vector<ParamEntry<S>> entries_;
};

/// Entry makers: the member it sets, its key, default, limits, unit and meaning.
template <typename S>
ParamEntry<S> number(const std::string& key, double S::*m, double def, Limits limits, const std::string& unit,
                     const std::string& meaning) {
  return {{key, def, limits, {}, unit, meaning},
          [m](const S& s) { return ParamValue(s.*m); },
          [m](S& s, const ParamValue& v) { s.*m = std::get<double>(v); }};
}
template <typename S, typename I>
ParamEntry<S> integer(const std::string& key, I S::*m, int def, Limits limits, const std::string& unit,
                      const std::string& meaning) {
  return {{key, def, limits, {}, unit, meaning},
          [m](const S& s) { return ParamValue(static_cast<int>(s.*m)); },
          [m](S& s, const ParamValue& v) { s.*m = static_cast<I>(std::get<int>(v)); }};
}
template <typename S>
ParamEntry<S> flag(const std::string& key, bool S::*m, bool def, const std::string& meaning) {
  return {{key, def, {}, {}, "", meaning},
          [m](const S& s) { return ParamValue(s.*m); },
          [m](S& s, const ParamValue& v) { s.*m = std::get<bool>(v); }};
}
/// A free string (a file name, a link name); `choices` restricts it when given.
template <typename S>
ParamEntry<S> text(const std::string& key, std::string S::*m, const std::string& def, const std::string& meaning,
                   std::vector<std::string> choices = {}) {
  return {{key, def, {}, std::move(choices), "", meaning},
          [m](const S& s) { return ParamValue(s.*m); },
          [m](S& s, const ParamValue& v) { s.*m = std::get<std::string>(v); }};
}
/// Marks a gain the PSO tuner may search.
template <typename S>
ParamEntry<S> tunable(ParamEntry<S> e) {
  e.info.tunable = true;
  return e;
}
/// A named choice stored as a C++ value (an enum, or a bool such as "adaptive"): names[i] <-> values[i].
template <typename S, typename E>
ParamEntry<S> choice(const std::string& key, E S::*m, E def, std::vector<std::pair<std::string, E>> names,
                     const std::string& meaning) {
  std::vector<std::string> labels;
  std::string def_label;
  for (const auto& n : names) {
    labels.push_back(n.first);
    if (n.second == def) def_label = n.first;
  }
  return {{key, def_label, {}, labels, "", meaning},
          [m, names](const S& s) {
            for (const auto& n : names)
              if (n.second == s.*m) return ParamValue(n.first);
            return ParamValue(std::string("?"));
          },
          [m, names](S& s, const ParamValue& v) {
            for (const auto& n : names)
              if (n.first == std::get<std::string>(v)) s.*m = n.second;
          }};
}

}  // namespace core
}  // namespace sowing_robot
