#include "sowing_robot/ros/component_params.h"

#include <XmlRpcValue.h>

#include <cmath>

#include "sowing_robot/ros/urdf_params.h"

namespace sowing_robot {

std::string loadRobotParams(const ros::NodeHandle& nh, core::RobotParams& out) {
  std::string key, xml;
  if (!nh.searchParam("robot_description", key) || !nh.getParam(key, xml))
    return "parameter robot_description (the URDF) is not set";
  const std::string e = robotParamsFromUrdf(xml, out);
  return e.empty() ? "" : "robot_description: " + e;
}

std::int64_t loadControlPeriod(ParamReader& p, std::string& error) {
  const double rate = p.get("control_rate", 1000.0);
  if (!(std::isfinite(rate) && rate >= 1.0 && rate <= 100000.0)) {
    error = "control_rate = " + std::to_string(rate) + " is outside the allowed range [1, 100000] Hz";
    return 0;
  }
  return static_cast<std::int64_t>(std::llround(1e9 / rate));
}

core::PlantDisturbance loadDisturbance(ParamReader& p) {
  core::PlantDisturbance d;
  d.sinusoidal = p.get("disturbance/sinusoidal", d.sinusoidal);
  d.amplitude = p.get("disturbance/amplitude", d.amplitude);
  d.frequency = p.get("disturbance/frequency", d.frequency);
  d.noise_std = p.get("noise/std", d.noise_std);
  d.seed = static_cast<std::uint64_t>(p.get("noise/seed", 1));
  d.mass_scale = p.get("mismatch/mass_scale", d.mass_scale);
  d.inertia_scale = p.get("mismatch/inertia_scale", d.inertia_scale);
  return d;
}

core::KanayamaGains loadKanayama(ParamReader& p) {
  core::KanayamaGains g;
  g.kx = p.get("kx", g.kx);
  g.ky = p.get("ky", g.ky);
  g.ktheta = p.get("ktheta", g.ktheta);
  return g;
}

core::SlidingModeParams loadSlidingMode(ParamReader& p, std::string& error) {
  core::SlidingModeParams s;
  const std::string mode = p.get("mode", "atsmc");
  if (mode != "atsmc" && mode != "tsmc") error = "mode = '" + mode + "' must be 'atsmc' or 'tsmc'";
  s.adaptive = mode == "atsmc";
  s.p = p.get("p", s.p);
  s.q = p.get("q", s.q);
  s.beta_v = p.get("beta_v", s.beta_v);
  s.beta_omega = p.get("beta_omega", s.beta_omega);
  s.k1 = p.get("k1", s.k1);
  s.k2 = p.get("k2", s.k2);
  s.eta1 = p.get("eta1", s.eta1);
  s.eta2 = p.get("eta2", s.eta2);
  s.rate_m = p.get("rate_m", s.rate_m);
  s.rate_i = p.get("rate_i", s.rate_i);
  s.m0_min = p.get("m0_min", s.m0_min);
  s.m0_max = p.get("m0_max", s.m0_max);
  s.i0_min = p.get("i0_min", s.i0_min);
  s.i0_max = p.get("i0_max", s.i0_max);
  s.m0_initial = p.get("m0_initial", s.m0_initial);
  s.i0_initial = p.get("i0_initial", s.i0_initial);
  s.max_torque = p.get("max_torque", s.max_torque);
  const std::string sw = p.get("switching", "sign");
  if (!core::SwitchFunction::parse(sw, s.switching.type) && error.empty())
    error = "switching = '" + sw + "' must be one of sign, sat, relay, atan, tanh";
  s.switching.width = p.get("switch_width", s.switching.width);
  return s;
}

core::Pose2D loadStartPose(ParamReader& p) {
  core::Pose2D s{-1.0, 0.0, 0.0};
  s.x = p.get("start/x", s.x);
  s.y = p.get("start/y", s.y);
  s.theta = p.get("start/theta", s.theta);
  return s;
}

core::PotentialFieldParams loadPotentialField(ParamReader& p, std::string& error) {
  core::PotentialFieldParams f;
  f.alpha = p.get("potential/alpha", f.alpha);
  f.beta = p.get("potential/beta", f.beta);
  f.influence_distance = p.get("potential/influence_distance", f.influence_distance);
  f.gain = p.get("potential/gain", f.gain);
  f.tangential_ratio = p.get("potential/tangential_ratio", f.tangential_ratio);
  f.nearest_side = p.get("potential/nearest_side", f.nearest_side);
  const std::string side = p.get("potential/avoid_side", "left");
  if (side != "left" && side != "right" && error.empty())
    error = "potential/avoid_side = '" + side + "' must be 'left' or 'right'";
  f.avoid_side = side == "right" ? core::AvoidSide::kRight : core::AvoidSide::kLeft;
  f.side_band = p.get("potential/side_band", f.side_band);
  f.core_fraction = p.get("potential/core_fraction", f.core_fraction);
  f.step = p.get("potential/step", f.step);
  f.heading_hold_speed = p.get("potential/heading_hold_speed", f.heading_hold_speed);
  return f;
}

core::FieldParams loadFieldParams(ParamReader& p, std::string& error) {
  core::FieldParams f;
  f.rows = p.get("field/rows", f.rows);
  f.row_length = p.get("field/row_length", f.row_length);
  f.row_spacing = p.get("field/row_spacing", f.row_spacing);
  f.start_x = p.get("field/start_x", f.start_x);
  f.start_y = p.get("field/start_y", f.start_y);
  f.heading = p.get("field/heading", f.heading);
  f.rows_to_left = p.get("field/rows_to_left", f.rows_to_left);
  f.row_speed = p.get("field/row_speed", f.row_speed);
  f.turn_speed = p.get("field/turn_speed", f.turn_speed);
  f.min_turn_radius = p.get("field/min_turn_radius", f.min_turn_radius);
  f.max_accel = p.get("field/max_accel", f.max_accel);
  f.max_curvature_rate = p.get("field/max_curvature_rate", f.max_curvature_rate);
  f.start_from_rest = p.get("field/start_from_rest", f.start_from_rest);
  f.potential = loadPotentialField(p, error);
  return f;
}

namespace {
/// A number (int or double) from an XmlRpc value; false for any other type.
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
}  // namespace

std::string loadObstacles(ParamReader& p, const std::string& key, std::vector<core::Obstacle>& out) {
  out.clear();
  p.allow(key);
  const std::string full = p.handle().resolveName(key);
  if (!p.handle().hasParam(key)) return "";
  XmlRpc::XmlRpcValue list;
  if (!p.handle().getParam(key, list) || list.getType() != XmlRpc::XmlRpcValue::TypeArray)
    return "parameter " + full + " must be a list of {x, y, radius} maps";
  for (int i = 0; i < list.size(); ++i) {
    const std::string name = full + "[" + std::to_string(i) + "]";
    XmlRpc::XmlRpcValue& item = list[i];
    if (item.getType() != XmlRpc::XmlRpcValue::TypeStruct) return name + " must be a map {x, y, radius}";
    core::Obstacle o;
    for (auto it = item.begin(); it != item.end(); ++it) {
      double* field = it->first == "x" ? &o.x : it->first == "y" ? &o.y : it->first == "radius" ? &o.radius : nullptr;
      if (!field) return name + ": unknown key '" + it->first + "' (allowed: x, y, radius)";
      if (!xmlNumber(it->second, *field)) return name + "/" + it->first + " must be a number";
    }
    if (!item.hasMember("x") || !item.hasMember("y")) return name + " needs both x and y";
    const std::string e = o.validate();
    if (!e.empty()) return name + ": " + e;
    out.push_back(o);
  }
  return "";
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
  sc.control_period_ns = loadControlPeriod(plant, e);
  sc.disturbance = loadDisturbance(plant);
  sc.start = loadStartPose(plant);
  duration = plant.get("duration", 25.0);
  sc.duration = duration;
  sc.kanayama = loadKanayama(kin);
  sc.sliding = loadSlidingMode(torque, e);
  if (!e.empty()) return e;
  return sc.validate();
}

}  // namespace sowing_robot
