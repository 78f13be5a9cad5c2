// Reading the benchmark's and the tuner's YAML files through the parameter tables: one error line naming
// the file and the key for a missing or unknown key, a wrong type or a value out of range (the messages the
// nodes give for the same keys). Used by scenario_loader.cpp and tune_config.cpp.
#pragma once

#include <cmath>
#include <cstdlib>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "sowing_robot/core/common/param_table.h"

namespace sowing_robot {
namespace scenario_file {
namespace yaml_reading {

using core::ParamTable;
using core::ParamValue;

[[noreturn]] inline void fail(const std::string& file, const std::string& what) {
  throw std::invalid_argument(file + ": " + what);
}

/// Refuses a key that appears twice in one mapping, anywhere in `node`: yaml-cpp keeps both and a lookup
/// finds the first, so the second block would be dropped without a word.
inline void refuseRepeatedKeys(const YAML::Node& node, const std::string& file, const std::string& where = "") {
  if (node.IsSequence()) {
    for (const auto& item : node) refuseRepeatedKeys(item, file, where);
  } else if (node.IsMap()) {
    std::set<std::string> seen;
    for (const auto& kv : node) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
      if (!seen.insert(key).second)
        fail(file, "key '" + where + key + "' appears twice (line " + std::to_string(kv.first.Mark().line + 1) +
                       "): merge the two blocks");
      refuseRepeatedKeys(kv.second, file, where + key + "/");
    }
  }
}

inline YAML::Node loadYaml(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    fail(path, "cannot read the file");
  } catch (const YAML::Exception& e) {
    fail(path, std::string("not valid YAML: ") + e.what());
  }
  refuseRepeatedKeys(root, path);
  return root;
}

/// Refuses a key of `map` not in `known` (the typo check), naming the allowed ones.
inline void onlyKeys(const YAML::Node& map, const std::set<std::string>& known, const std::string& file,
                     const std::string& where) {
  if (!map.IsMap()) fail(file, where + " must be a mapping");
  for (const auto& kv : map) {
    const std::string key = kv.first.as<std::string>();
    if (known.count(key)) continue;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    fail(file, "unknown key '" + where + key + "' (known under '" + (where.empty() ? "/" : where) + "': " + list + ")");
  }
}

inline YAML::Node required(const YAML::Node& map, const std::string& key, const std::string& file,
                           const std::string& where) {
  const YAML::Node n = map[key];
  if (!n) fail(file, "missing key '" + where + key + "'");
  return n;
}

inline double toDouble(const YAML::Node& n, const std::string& file, const std::string& key) {
  if (!n.IsScalar()) fail(file, key + " must be a number");
  const std::string t = n.Scalar();
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || *end != '\0' || !std::isfinite(v)) fail(file, key + " = '" + t + "' is not a finite number");
  return v;
}

/// A scalar as the parameter's type (that of its default).
inline ParamValue toParamValue(const YAML::Node& n, const ParamValue& like, const std::string& file,
                               const std::string& key) {
  if (!n.IsScalar()) fail(file, key + " must be a single value");
  const std::string t = n.Scalar();
  if (std::holds_alternative<bool>(like)) {
    if (t == "true" || t == "True") return true;
    if (t == "false" || t == "False") return false;
    fail(file, key + " = '" + t + "' is not a bool");
  }
  if (std::holds_alternative<int>(like)) {
    char* end = nullptr;
    const long v = std::strtol(t.c_str(), &end, 10);
    if (t.empty() || *end != '\0') fail(file, key + " = '" + t + "' is not an integer");
    return static_cast<int>(v);
  }
  if (std::holds_alternative<double>(like)) return toDouble(n, file, key);
  return t;
}

/// A scalar whose parameter type is not known here (setControllerParam checks it against its table): a
/// bool, an integer (a table that wants a double takes it as one), a finite number, or else text.
inline ParamValue toParamValue(const YAML::Node& n, const std::string& file, const std::string& key) {
  if (!n.IsScalar()) fail(file, key + " must be a single value");
  const std::string t = n.Scalar();
  if (t == "true" || t == "True") return true;
  if (t == "false" || t == "False") return false;
  char* end = nullptr;
  const long i = std::strtol(t.c_str(), &end, 10);
  if (!t.empty() && *end == '\0') return static_cast<int>(i);
  const double v = std::strtod(t.c_str(), &end);
  if (!t.empty() && *end == '\0') {
    if (!std::isfinite(v)) fail(file, key + " = '" + t + "' is not a finite number");
    return v;
  }
  return t;
}

/// Flattens nested mappings into table keys joined by '/': {field: {rows: 3}} -> "field/rows".
inline void flatten(const YAML::Node& map, const std::string& prefix,
                    std::vector<std::pair<std::string, YAML::Node>>& out) {
  for (const auto& kv : map) {
    const std::string key = prefix + kv.first.as<std::string>();
    if (kv.second.IsMap())
      flatten(kv.second, key + "/", out);
    else
      out.emplace_back(key, kv.second);
  }
}

/// Sets every (key, value) through `table` on s; unknown keys and bad values refused; keys in `skip` are
/// left to the caller.
template <typename S>
void applyKeys(const ParamTable<S>& table, const std::vector<std::pair<std::string, YAML::Node>>& keys, S& s,
               const std::string& file, const std::string& where, const std::set<std::string>& skip = {}) {
  for (const auto& kv : keys) {
    if (skip.count(kv.first)) continue;
    const auto* entry = table.find(kv.first);
    if (!entry) {
      std::string list;
      for (const auto& e : table.entries()) list += (list.empty() ? "" : ", ") + e.info.key;
      fail(file, "unknown key '" + where + kv.first + "' (known: " + list + ")");
    }
    const ParamValue v = toParamValue(kv.second, entry->info.default_value, file, where + kv.first);
    const std::string error = entry->info.check(v, where);
    if (!error.empty()) fail(file, error);
    entry->set(s, v);
  }
}

/// A mapping `where` whose keys (nested ones joined by '/') are the table's keys.
template <typename S>
void applyGroup(const ParamTable<S>& table, const YAML::Node& group, S& s, const std::string& file,
                const std::string& where, const std::set<std::string>& skip = {}) {
  if (!group.IsMap()) fail(file, where + " must be a mapping");
  std::vector<std::pair<std::string, YAML::Node>> keys;
  flatten(group, "", keys);
  applyKeys(table, keys, s, file, where + "/", skip);
}

/// A block whose keys are a node's table keys under `prefix` (traction: {mu_peak: 0.2} -> "traction/mu_peak"):
/// unknown keys and bad values refused with the table's key in the line.
template <typename S>
void applyTableBlock(const ParamTable<S>& table, const YAML::Node& group, S& s, const std::string& file,
                     const std::string& prefix) {
  if (!group.IsMap()) fail(file, prefix + " must be a mapping");
  std::vector<std::pair<std::string, YAML::Node>> keys;
  flatten(group, prefix + "/", keys);
  applyKeys(table, keys, s, file, "");
}

}  // namespace yaml_reading
}  // namespace scenario_file
}  // namespace sowing_robot
