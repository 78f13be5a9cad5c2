#include "sowing_robot/ros/common/component_params.h"

#include <XmlRpcValue.h>

#include <algorithm>
#include <cmath>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/ros/common/urdf_params.h"

namespace sowing_robot {

std::string loadRobotParams(const ros::NodeHandle& nh, core::RobotParams& out) {
  std::string key, xml;
  if (!nh.searchParam("robot_description", key) || !nh.getParam(key, xml))
    return "parameter robot_description (the URDF) is not set";
  const std::string e = robotParamsFromUrdf(xml, out);
  return e.empty() ? "" : "robot_description: " + e;
}

core::RunSettings loadRunSettings(const ros::NodeHandle& nh, ParamReader& own,
                                  const std::vector<std::string>& own_keys) {
  ParamReader run(ros::NodeHandle(nh, "run"));
  core::RunSettings settings;
  loadTable(run, core::RunSettings::table(), settings);
  if (!run.error().empty()) own.fail(run.error());
  for (const auto& e : core::RunSettings::table().entries()) {
    if (!own.handle().hasParam(e.info.key)) continue;
    if (std::find(own_keys.begin(), own_keys.end(), e.info.key) != own_keys.end()) continue;
    const core::ParamValue mine = own.get(e.info.key, e.info.default_value), theirs = e.get(settings);
    if (mine != theirs)
      own.fail(own.handle().resolveName(e.info.key) + " = " + core::formatValue(mine) + " disagrees with " +
               run.handle().resolveName(e.info.key) + " = " + core::formatValue(theirs) +
               " (a run-wide setting: set it once, in run/)");
  }
  return settings;
}

bool xmlNumber(const XmlRpc::XmlRpcValue& v, double& out) {
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    out = static_cast<const double&>(v);
    return true;
  }
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    out = static_cast<const int&>(v);
    return true;
  }
  return false;
}

std::string forEachMap(ParamReader& p, const std::string& key, const std::string& shape, const MapVisitor& visit) {
  p.allow(key);
  const std::string full = p.handle().resolveName(key);
  if (!p.handle().hasParam(key)) return "";
  XmlRpc::XmlRpcValue list;
  if (!p.handle().getParam(key, list) || list.getType() != XmlRpc::XmlRpcValue::TypeArray)
    return "parameter " + full + " must be a list of " + shape + " maps";
  for (int i = 0; i < list.size(); ++i) {
    const std::string name = full + "[" + std::to_string(i) + "]";
    XmlRpc::XmlRpcValue& item = list[i];
    if (item.getType() != XmlRpc::XmlRpcValue::TypeStruct) return name + " must be a map " + shape;
    const std::string e = visit(name, item);
    if (!e.empty()) return e;
  }
  return "";
}

MapMember numberMember(const std::string& key, double& out) {
  return {key, [key, &out](XmlRpc::XmlRpcValue& value, const std::string& name) -> std::string {
            return xmlNumber(value, out) ? "" : name + "/" + key + " must be a number";
          }};
}

std::string readMembers(XmlRpc::XmlRpcValue& map, const std::string& name, const std::vector<MapMember>& members) {
  for (auto it = map.begin(); it != map.end(); ++it) {
    const auto m = std::find_if(members.begin(), members.end(), [&](const MapMember& c) { return c.key == it->first; });
    if (m == members.end()) {
      std::string allowed;
      for (const MapMember& c : members) allowed += (allowed.empty() ? "" : ", ") + c.key;
      return name + ": unknown key '" + it->first + "' (allowed: " + allowed + ")";
    }
    const std::string e = m->read(it->second, name);
    if (!e.empty()) return e;
  }
  return "";
}

std::string loadObstacles(ParamReader& p, const std::string& key, std::vector<core::Obstacle>& out) {
  out.clear();
  return forEachMap(p, key, "{x, y, radius}", [&out](const std::string& name, XmlRpc::XmlRpcValue& item) {
    core::Obstacle o;
    const std::string e =
        readMembers(item, name, {numberMember("x", o.x), numberMember("y", o.y), numberMember("radius", o.radius)});
    if (!e.empty()) return e;
    if (!item.hasMember("x") || !item.hasMember("y")) return name + " needs both x and y";
    const std::string invalid = o.validate();
    if (!invalid.empty()) return name + ": " + invalid;
    out.push_back(o);
    return std::string();
  });
}

namespace {
/// The URDF in robot_description, searched upwards from p's namespace.
std::string robotDescription(ParamReader& p, std::string& xml) {
  p.allow("robot_description");
  std::string key;
  if (!p.handle().searchParam("robot_description", key) || !p.handle().getParam(key, xml))
    return "parameter robot_description (the URDF) is not set";
  return "";
}
}  // namespace

std::string loadToolRunOut(ParamReader& p, const ros::NodeHandle& nh, double& run_out) {
  std::string xml;
  std::string error = robotDescription(p, xml);
  // The seed drill's tool point: seed_drill/tool_link, where sim.launch loads config/seed_drill.yaml, as plant_sim
  // reads it.
  std::string tool_link = "tool_link";
  nh.param<std::string>("seed_drill/tool_link", tool_link, tool_link);
  if (error.empty()) error = toolRunOutFromUrdf(xml, tool_link, run_out);
  return error;
}

std::string loadFieldPlan(ParamReader& p, const ros::NodeHandle& nh, const core::Pose2D& start,
                          core::FieldParams& field, std::vector<core::Obstacle>& obstacles) {
  loadTable(p, core::fieldTable(), field);
  std::string error = loadObstacles(p, "obstacles", obstacles);
  // The plan keeps the body clear, not the axle point: the obstacles are inflated by the footprint's
  // circumscribed radius, from the URDF's collision geometry (the one source of the robot's shape).
  std::string xml;
  core::Footprint footprint;
  if (error.empty()) error = robotDescription(p, xml);
  if (error.empty()) error = footprintFromUrdf(xml, footprint);
  field.avoidance.footprint_radius = footprint.circumscribedRadius();
  // The rows are driven on until the seed drill's tool point reaches their ends, so each row is sown to its end.
  if (error.empty()) error = loadToolRunOut(p, nh, field.run_out);
  // The reference starts where the robot does (run/start) and joins the first row on a bounded approach.
  field.start_pose = start;
  if (error.empty() && p.error().empty()) error = field.validate();
  return error;
}

void requireValid(const ParamReader& p, const std::string& validate_message) {
  if (!p.error().empty()) refuseToStart(p.error());
  const std::string unknown = p.unknownKeys();
  if (!unknown.empty()) refuseToStart(unknown);
  if (!validate_message.empty()) refuseToStart(validate_message);
}

std::string loadPipelineScenario(core::Scenario& sc, double& duration) {
  ParamReader plant(ros::NodeHandle("/plant_sim")), kin(ros::NodeHandle("/kinematic_controller")),
      torque(ros::NodeHandle("/torque_controller"));
  std::string e = loadRobotParams(ros::NodeHandle(), sc.robot);
  if (!e.empty()) return e;
  const core::RunSettings run = loadRunSettings(ros::NodeHandle(), plant);
  core::PlantSimSettings plant_settings;
  core::KinematicControllerSettings kin_settings;
  core::TorqueControllerSettings torque_settings;
  loadTable(plant, core::PlantSimSettings::table(), plant_settings);
  loadTable(kin, core::KinematicControllerSettings::table(), kin_settings);
  loadTable(torque, core::TorqueControllerSettings::table(), torque_settings);
  e = core::firstError({plant.error(), kin.error(), torque.error()});
  if (!e.empty()) return e;
  sc.control_period_ns = run.periodNs();
  sc.disturbance = plant_settings.disturbance;
  sc.start = run.start();
  duration = run.duration;
  sc.duration = duration;
  core::copySlot(sc, kin_settings, core::ControllerParam::Slot::outer);  // the pair as the nodes run it
  core::copySlot(sc, torque_settings, core::ControllerParam::Slot::inner);
  sc.hold = torque_settings.hold;
  return sc.validate();
}

}  // namespace sowing_robot
