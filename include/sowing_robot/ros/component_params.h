// Loading through the parameter tables (core/param_table.h): every key, default, range and unit comes
// from the component's table, so nodes, the PSO tuner and the pipeline test read a gain the same way.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <ros/console.h>

#include "sowing_robot/core/field.h"
#include "sowing_robot/core/node_settings.h"
#include "sowing_robot/core/robot_params.h"
#include "sowing_robot/core/runner.h"
#include "sowing_robot/ros/param_reader.h"

namespace sowing_robot {

/// Robot geometry and inertia from the URDF in `robot_description` (searched upwards from nh).
std::string loadRobotParams(const ros::NodeHandle& nh, core::RobotParams& out);

/// Reads every entry of `table` (its keys under `prefix`) into `out`: an absent key keeps the table's
/// default; a wrong type or an out-of-range value becomes the reader's first error, naming the full key.
template <typename S>
void loadTable(ParamReader& p, const core::ParamTable<S>& table, S& out, const std::string& prefix = "") {
  for (const auto& e : table.entries()) {
    const std::string key = prefix + e.info.key;
    const bool had_error = !p.error().empty();
    const core::ParamValue v = p.get(key, e.info.default_value);
    if (!had_error && !p.error().empty()) continue;  // a type error, recorded by the reader
    const std::string bad = e.info.check(v, p.handle().getNamespace() + "/" + prefix);
    if (!bad.empty()) {
      p.fail(bad);
      continue;
    }
    e.set(out, v);
  }
}

/// The run-wide settings (`run/...` relative to nh: mode, control_rate, duration, odom_frame,
/// base_frame). A node that also has one of them among its private parameters (`own`) must agree with
/// the run's value, else the reader's error names both; keys in `own_keys` are the node's own
/// parameters of the same name (torque_controller's `mode`: atsmc | tsmc) and are not compared.
core::RunSettings loadRunSettings(const ros::NodeHandle& nh, ParamReader& own,
                                  const std::vector<std::string>& own_keys = {});

/// "<node>: key value unit, ..." of the values in force, logged once at start-up.
template <typename S>
void logSettings(const char* node, const core::ParamTable<S>& table, const S& s, const std::string& prefix = "") {
  ROS_INFO("%s: %s", node, table.describe(s, prefix).c_str());
}

/// The list `key` of {x, y, radius} maps (radius optional, default core::Obstacle's); marks `key` as read.
/// Returns "" or one line naming the bad entry (absent key: empty list).
/// A number (int or double) from an XmlRpc value; false for any other type.
bool xmlNumber(const XmlRpc::XmlRpcValue& v, double& out);

std::string loadObstacles(ParamReader& p, const std::string& key, std::vector<core::Obstacle>& out);

/// Everything one node needs checked: reader errors, unknown keys, then the given validate() text.
/// Refuses to start on the first problem: throws badParameter (node_failure.h).
void requireValid(const ParamReader& p, const std::string& validate_message);

/// The scenario the node pipeline runs, read from the run settings and the nodes' own namespaces
/// (/plant_sim, /kinematic_controller, /torque_controller): what the in-process runner needs to repeat a run,
/// the outer/inner choice and every controller's parameters included.
std::string loadPipelineScenario(core::Scenario& sc, double& duration);

}  // namespace sowing_robot
