// dynamic_reconfigure <-> parameter table, by name: every field of a .cfg is the table entry with the
// same key (test_reconfigure_tables checks that each exists, with the table's default and range), so
// the live-tunable gains are not listed again in the node.
#pragma once

#include <dynamic_reconfigure/Config.h>

#include <string>

#include "sowing_robot/core/param_table.h"

namespace sowing_robot {

/// The values in force, `s`, into a dynamic_reconfigure config (fields without a table entry keep theirs).
template <typename Config, typename S>
void toConfig(const core::ParamTable<S>& table, const S& s, Config& config) {
  dynamic_reconfigure::Config msg;
  for (const auto& d : Config::__getParamDescriptions__()) {
    const core::ParamEntry<S>* e = table.find(d->name);
    if (!e) continue;
    const core::ParamValue v = e->get(s);
    if (const double* x = std::get_if<double>(&v)) {
      dynamic_reconfigure::DoubleParameter p;
      p.name = d->name;
      p.value = *x;
      msg.doubles.push_back(p);
    } else if (const int* i = std::get_if<int>(&v)) {
      dynamic_reconfigure::IntParameter p;
      p.name = d->name;
      p.value = *i;
      msg.ints.push_back(p);
    } else if (const bool* b = std::get_if<bool>(&v)) {
      dynamic_reconfigure::BoolParameter p;
      p.name = d->name;
      p.value = *b;
      msg.bools.push_back(p);
    } else {
      dynamic_reconfigure::StrParameter p;
      p.name = d->name;
      p.value = std::get<std::string>(v);
      msg.strs.push_back(p);
    }
  }
  config.__fromMessage__(msg);
}

/// A requested config into `s`, each value checked against its entry: "" or the first bad value as one
/// line (then `s` may be partly changed: callers work on a copy).
template <typename Config, typename S>
std::string fromConfig(const core::ParamTable<S>& table, const Config& config, S& s) {
  dynamic_reconfigure::Config msg;
  config.__toMessage__(msg);
  auto apply = [&](const std::string& name, const core::ParamValue& v) -> std::string {
    const core::ParamEntry<S>* e = table.find(name);
    if (!e) return "";
    const std::string bad = e->info.check(v);
    if (!bad.empty()) return bad;
    e->set(s, v);
    return "";
  };
  std::string error;
  for (const auto& p : msg.doubles)
    if (error.empty()) error = apply(p.name, p.value);
  for (const auto& p : msg.ints)
    if (error.empty()) error = apply(p.name, static_cast<int>(p.value));
  for (const auto& p : msg.bools)
    if (error.empty()) error = apply(p.name, static_cast<bool>(p.value));
  for (const auto& p : msg.strs)
    if (error.empty()) error = apply(p.name, p.value);
  return error;
}

}  // namespace sowing_robot
