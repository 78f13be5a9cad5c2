#include "sowing_robot/ros/component_params.h"

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
