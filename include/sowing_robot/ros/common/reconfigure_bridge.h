// dynamic_reconfigure <-> parameter table, by name: every field of a .cfg is the table entry with the
// same key (test_reconfigure_tables checks that each exists, with the table's default and range), so
// the live-tunable gains are not listed again in the node.
#pragma once

#include <dynamic_reconfigure/Config.h>
#include <dynamic_reconfigure/server.h>
#include <ros/console.h>
#include <boost/thread/recursive_mutex.hpp>

#include <memory>
#include <stdexcept>
#include <string>

#include "sowing_robot/core/common/param_table.h"

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

/// Every entry of `table` equal in `a` and `b` (exactly: a gain changed in its last digit is a change).
template <typename S>
bool sameValues(const core::ParamTable<S>& table, const S& a, const S& b) {
  for (const auto& e : table.entries())
    if (!(e.get(a) == e.get(b))) return false;
  return true;
}

/// The body of a live change: `config` over a copy of `in_force`, validated, then handed to `apply` (which
/// may throw std::invalid_argument, keeping the old values); nothing when it changes no value. A refused change is
/// logged as one WARN naming the key and `config` is set back to the values in force (the server then reports and
/// stores those).
template <typename Config, typename S, typename Apply>
void applyReconfigure(const char* node, const core::ParamTable<S>& table, const S& in_force, Config& config,
                      Apply apply) {
  S p = in_force;
  std::string error = fromConfig(table, config, p);
  if (error.empty() && sameValues(table, p, in_force)) return;  // the server's first call, or no change
  if (error.empty()) error = p.validate();
  if (error.empty()) {
    try {
      apply(p);
    } catch (const std::invalid_argument& e) {
      error = e.what();
    }
  }
  if (!error.empty()) {
    ROS_WARN("%s: rejected gain change: %s; keeping the previous gains", node, error.c_str());
    toConfig(table, in_force, config);
    return;
  }
  ROS_INFO("%s: gains now %s", node, table.describe(p).c_str());
}

/// A dynamic_reconfigure server that locks a mutex of its own: one constructed without would log a WARN
/// ("updateConfig() called on a dynamic_reconfigure::Server that provides its own mutex") at every start,
/// where the node hands it the values in force.
template <typename Config>
struct ReconfigureServer {
  explicit ReconfigureServer(const ros::NodeHandle& nh) : server(mutex, nh) {}
  boost::recursive_mutex mutex;  // declared first: built before the server, destroyed after it
  dynamic_reconfigure::Server<Config> server;
};

/// A dynamic_reconfigure server on `nh` that starts from the values in force (not the .cfg's defaults,
/// so its first callback changes nothing) and calls `callback(config)` on every change.
template <typename Config, typename S, typename Callback>
std::unique_ptr<ReconfigureServer<Config>> startReconfigure(const ros::NodeHandle& nh, const core::ParamTable<S>& table,
                                                            const S& in_force, Callback callback) {
  auto reconfigure = std::make_unique<ReconfigureServer<Config>>(nh);
  Config c;
  toConfig(table, in_force, c);
  reconfigure->server.updateConfig(c);
  reconfigure->server.setCallback([callback](Config& config, uint32_t) { callback(config); });
  return reconfigure;
}

}  // namespace sowing_robot
