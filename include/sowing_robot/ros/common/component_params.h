// Loading through the parameter tables (core/common/param_table.h): every key, default, range and unit comes
// from the component's table, so nodes, the PSO tuner and the pipeline test read a gain the same way.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <ros/console.h>

#include "sowing_robot/core/model/robot_params.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/settings/node_settings.h"
#include "sowing_robot/core/simulation/runner.h"
#include "sowing_robot/ros/common/param_reader.h"

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

/// A number (int or double) from an XmlRpc value; false for any other type.
bool xmlNumber(const XmlRpc::XmlRpcValue& v, double& out);

/// Reads one map of a list-of-maps parameter: gets the map and its name for errors ("<full key>[i]");
/// returns "" or one line naming what is wrong.
using MapVisitor = std::function<std::string(const std::string& name, XmlRpc::XmlRpcValue& map)>;

/// Walks the list-of-maps parameter `key` (relative to p; marked as read). Absent: nothing to walk, "".
/// Not a list: "parameter <full> must be a list of <shape> maps"; an item not a map: "<full>[i] must be a
/// map <shape>" (shape e.g. "{x, y, radius}"); else each map goes to `visit`, in order, and its first
/// error is returned.
std::string forEachMap(ParamReader& p, const std::string& key, const std::string& shape, const MapVisitor& visit);

/// One allowed key of a map and how its value is read: read(value, map's name) returns "" or the error.
struct MapMember {
  std::string key;
  std::function<std::string(XmlRpc::XmlRpcValue& value, const std::string& name)> read;
};

/// A member that is a number (int or double) into `out`; otherwise "<name>/<key> must be a number".
MapMember numberMember(const std::string& key, double& out);

/// Reads every member of `map` with its MapMember; a key with none: "<name>: unknown key 'k' (allowed:
/// <the members' keys>)". Returns the first error ("" if none); absent members are left as they were.
std::string readMembers(XmlRpc::XmlRpcValue& map, const std::string& name, const std::vector<MapMember>& members);

/// The list `key` of {x, y, radius} maps (radius optional, default core::Obstacle's); marks `key` as read.
/// Returns "" or one line naming the bad entry (absent key: empty list).
std::string loadObstacles(ParamReader& p, const std::string& key, std::vector<core::Obstacle>& out);

/// How far the seed drill's tool point (`seed_drill/tool_link`, relative to nh) trails base_link in the URDF of
/// robot_description (searched upwards from p's namespace) [m]: the run-out a field's rows are driven on by.
std::string loadToolRunOut(ParamReader& p, const ros::NodeHandle& nh, double& run_out);

/// What reference_generator plans a field from with type field, read as it reads it (and the lockstep tester, to
/// plan the same field in-process): field/... and potential/... (fieldTable()) and the obstacles list from p (the
/// node's namespace); the footprint's circumscribed radius (avoidance/footprint_radius: the obstacles are inflated
/// by it) and the last row's run-out to the seed drill's tool point (`seed_drill/tool_link`, relative to nh) from
/// the URDF in robot_description (searched upwards from p's namespace); `start` as the start pose. Then
/// FieldParams::validate() if nothing failed before. Returns "" or the first error (p's own errors stay in p).
std::string loadFieldPlan(ParamReader& p, const ros::NodeHandle& nh, const core::Pose2D& start,
                          core::FieldParams& field, std::vector<core::Obstacle>& obstacles);

/// Everything one node needs checked: reader errors, unknown keys, then the given validate() text.
/// Refuses to start on the first problem: throws badParameter (node_failure.h).
void requireValid(const ParamReader& p, const std::string& validate_message);

/// The scenario the node pipeline runs, read from the run settings and the nodes' own namespaces
/// (/plant_sim, /kinematic_controller, /torque_controller): what the in-process runner needs to repeat a run,
/// the outer/inner choice and every controller's parameters included.
std::string loadPipelineScenario(core::Scenario& sc, double& duration);

}  // namespace sowing_robot
