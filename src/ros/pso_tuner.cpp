#include "sowing_robot/ros/pso_tuner.h"

#include <std_msgs/Float64MultiArray.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/ros/common/component_params.h"

namespace sowing_robot {

namespace {

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

std::string g(double v) { return fmt("%.6g", v); }

std::string defaultOutput() {
  const char* ros_home = std::getenv("ROS_HOME");
  if (ros_home && *ros_home) return std::string(ros_home) + "/tuned_gains.yaml";
  const char* home = std::getenv("HOME");
  return std::string(home && *home ? home : ".") + "/.ros/tuned_gains.yaml";
}

/// ~gains: a list of {name: str, lower: number, upper: number}. "" or one line naming the bad entry.
std::string parseGains(const ros::NodeHandle& pnh, const core::Scenario& base, std::vector<core::GainBounds>& out) {
  const std::string full = pnh.resolveName("gains");
  if (!pnh.hasParam("gains")) {  // every tunable gain of the pair, in its search bounds (core/evaluation/tuning.h)
    out = core::defaultGainBounds(base);
    return "";
  }
  XmlRpc::XmlRpcValue list;
  pnh.getParam("gains", list);
  if (list.getType() != XmlRpc::XmlRpcValue::TypeArray)
    return "parameter " + full + " must be a list of {name, lower, upper}";
  out.clear();
  for (int i = 0; i < list.size(); ++i) {
    XmlRpc::XmlRpcValue& e = list[i];
    const std::string at = full + "[" + std::to_string(i) + "]";
    if (e.getType() != XmlRpc::XmlRpcValue::TypeStruct) return at + " must be a map {name, lower, upper}";
    core::GainBounds b;
    for (auto it = e.begin(); it != e.end(); ++it) {
      const std::string& key = it->first;
      XmlRpc::XmlRpcValue& v = it->second;
      if (key == "name") {
        if (v.getType() != XmlRpc::XmlRpcValue::TypeString) return at + "/name must be a string";
        b.name = static_cast<std::string>(v);
      } else if (key == "lower" || key == "upper") {
        double x;
        if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble)
          x = static_cast<double>(v);
        else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt)
          x = static_cast<int>(v);
        else
          return at + "/" + key + " must be a number";
        (key == "lower" ? b.lower : b.upper) = x;
      } else {
        return at + ": unknown key '" + key + "' (expected name, lower, upper)";
      }
    }
    for (const char* k : {"name", "lower", "upper"})
      if (!e.hasMember(k)) return at + " has no '" + k + "'";
    out.push_back(b);
  }
  return "";
}

}  // namespace

std::string yamlFloat(double v) { return core::yamlFloat(v); }

std::string writeGainsYaml(const std::string& path, const std::string& header, const core::Scenario& tuned,
                           const std::vector<core::GainBounds>& searched) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path target(path);
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
  if (ec) return "cannot create " + target.parent_path().string() + ": " + ec.message();
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream f(tmp);
    if (!f) return "cannot open " + tmp + " for writing";
    f << header << core::gainsYaml(tuned, searched);
    f.flush();
    if (!f) return "write to " + tmp + " failed";
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return "cannot rename " + tmp + " to " + path;
  }
  return "";
}

PsoTuner::PsoTuner(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  core::PsoTunerSettings settings;
  loadTable(p, core::PsoTunerSettings::table(), settings);
  pso_.particles = settings.particles;
  pso_.iterations = settings.iterations;
  pso_.seed = static_cast<std::uint64_t>(settings.seed);
  pso_.threads = settings.threads;
  pso_.max_velocity_fraction = settings.velocity_clamp;
  pso_.w_max = settings.w_max;
  pso_.w_min = settings.w_min;
  pso_.c1 = settings.c1;
  pso_.c2 = settings.c2;
  core::parseCostType(settings.cost, objective_.cost);  // one of the table's choices
  objective_.torque_weight = settings.torque_weight;
  objective_.chattering_weight = settings.chattering_weight;
  output_ = settings.output.empty() ? defaultOutput() : settings.output;
  p.allow("gains");
  p.allow("gains/");

  // The base scenario, read with the nodes' own tables from the nodes' namespaces; duration and rate are
  // the tuner's own (an evaluation need not be as long as the run).
  ParamReader plant(ros::NodeHandle("/plant_sim")), kin(ros::NodeHandle("/kinematic_controller")),
      torque(ros::NodeHandle("/torque_controller")), refp(ros::NodeHandle("/reference_generator")),
      runp(ros::NodeHandle("/run"));  // the start pose (the tuner's own duration and rate are its own keys)
  core::RunSettings run;
  loadTable(runp, core::RunSettings::table(), run);
  const std::string robot_error = loadRobotParams(pnh, base_.robot);
  core::PlantSimSettings plant_settings;
  core::KinematicControllerSettings kin_settings;
  core::TorqueControllerSettings torque_settings;
  core::ReferenceGeneratorSettings ref_settings;
  loadTable(plant, core::PlantSimSettings::table(), plant_settings);
  loadTable(kin, core::KinematicControllerSettings::table(), kin_settings);
  loadTable(torque, core::TorqueControllerSettings::table(), torque_settings);
  loadTable(refp, core::ReferenceGeneratorSettings::table(), ref_settings);
  base_.duration = settings.duration;
  base_.control_period_ns = static_cast<std::int64_t>(std::llround(1e9 / settings.control_rate));
  base_.start = run.start();
  base_.disturbance = plant_settings.disturbance;
  base_.kanayama = kin_settings.kanayama;
  base_.sliding = torque_settings.sliding;
  base_.sliding.adaptive = settings.adaptive;
  // The baselines' parameters, nested under the same nodes as the gains YAML writes them (core::gainKey).
  loadTable(kin, core::purePursuitTable(), base_.pure_pursuit, "pure_pursuit/");
  loadTable(torque, core::wheelPidTable(), base_.pid, "pid/");
  std::string pair_error;
  if (!settings.controller.empty())
    pair_error = core::parseControllerPair(settings.controller, base_.outer, base_.inner, base_.sliding.adaptive);
  line_v_ = ref_settings.line_v_r;
  line_y_ = ref_settings.line_y;
  line_x0_ = ref_settings.line_x0;
  reference_ = core::LineReference(line_v_, line_y_, line_x0_);

  const std::string gains_error = pair_error.empty() ? parseGains(pnh, base_, gains_) : "";
  std::string e = core::firstError({runp.error(), plant.error(), kin.error(), torque.error(), refp.error(), robot_error,
                                    settings.validate(), pair_error, gains_error});
  if (e.empty())
    e = core::firstError({base_.validate(), core::validateGainBounds(base_, gains_), objective_.validate()});
  if (e.empty()) {
    for (const auto& b : gains_) {
      pso_.lower.push_back(b.lower);
      pso_.upper.push_back(b.upper);
    }
    e = pso_.validate();
  }
  // Type errors of our own keys first, then typos among them, then ranges.
  requireValid(p, e);

  progress_pub_ = nh.advertise<std_msgs::Float64MultiArray>("pso/progress", 10, true);
  std::string dims;
  for (const auto& b : gains_)
    dims += (dims.empty() ? "" : ", ") + b.name + " [" + g(b.lower) + ", " + g(b.upper) + "]";
  logSettings("pso_tuner", core::PsoTunerSettings::table(), settings);
  ROS_INFO("pso_tuner: %d evaluation thread(s)", core::psoThreads(pso_));
  ROS_INFO("pso_tuner: scenario %s", scenarioText().c_str());
  ROS_INFO("pso_tuner: searching %s", dims.c_str());
  ROS_INFO("pso_tuner: output %s", output_.c_str());
}

std::string PsoTuner::scenarioText() const {
  const core::PlantDisturbance& d = base_.disturbance;
  std::string s = g(base_.duration) + " s at " + g(1e9 / static_cast<double>(base_.control_period_ns)) + " Hz, " +
                  base_.controllerName() + adaptationText() + ", start (" + g(base_.start.x) + ", " + g(base_.start.y) +
                  ", " + g(base_.start.theta) + "), line x = " + g(line_x0_) + " + " + g(line_v_) +
                  " t, y = " + g(line_y_) + ", ";
  s += d.sinusoidal ? "sinusoidal disturbance A " + g(d.amplitude) + " N.m w " + g(d.frequency) + " rad/s"
                    : "no sinusoidal disturbance";
  s += ", mismatch mass x" + g(d.mass_scale) + " inertia x" + g(d.inertia_scale);
  s += ", noise std " + g(d.noise_std) + " N.m (seed " + std::to_string(d.seed) + ")";
  return s;
}

std::string PsoTuner::adaptationText() const {
  if (base_.inner != core::InnerKind::sliding_mode || !base_.sliding.adaptive ||
      base_.sliding.adaptation == core::Adaptation::mass_inertia)
    return "";
  return " (adaptation eq_4_22)";
}

std::string PsoTuner::loadArgs() const {
  // sim.launch's controller:=atsmc|tsmc for the thesis pair; the baselines' outer:= / inner:= selection.
  if (base_.outer == core::OuterKind::kanayama && base_.inner == core::InnerKind::sliding_mode)
    return std::string("controller:=") + (base_.sliding.adaptive ? "atsmc" : "tsmc");
  return std::string("outer:=") + core::outerName(base_.outer) +
         " inner:=" + core::innerName(base_.inner, base_.sliding.adaptive);
}

void PsoTuner::onProgress(const core::PsoProgress& p) {
  if (!ros::ok()) throw std::runtime_error("interrupted");
  if (p.iteration == 0) initial_best_ = p.best_cost;
  ROS_INFO("pso_tuner: iteration %d/%d  best cost %.6g  (initial %.6g)  elapsed %.2f s  ETA %.2f s", p.iteration,
           p.iterations, p.best_cost, initial_best_, p.elapsed_s, p.eta_s);
  std_msgs::Float64MultiArray m;
  std::string labels = "iteration,iterations,best_cost,initial_best_cost,elapsed_s,eta_s,evaluations";
  m.data = {static_cast<double>(p.iteration),
            static_cast<double>(p.iterations),
            p.best_cost,
            initial_best_,
            p.elapsed_s,
            p.eta_s,
            static_cast<double>(pso_.particles) * (p.iteration + 1)};
  for (std::size_t d = 0; d < gains_.size(); ++d) {
    labels += "," + gains_[d].name;
    m.data.push_back((*p.best_position)[d]);
  }
  m.layout.dim.resize(1);
  m.layout.dim[0].label = labels;
  m.layout.dim[0].size = static_cast<std::uint32_t>(m.data.size());
  m.layout.dim[0].stride = static_cast<std::uint32_t>(m.data.size());
  progress_pub_.publish(m);
}

int PsoTuner::run() {
  core::TuningResult r;
  try {
    r = core::tuneGains(base_, reference_, gains_, objective_, pso_,
                        [this](const core::PsoProgress& p) { onProgress(p); });
  } catch (const std::exception& e) {
    ROS_ERROR("pso_tuner: stopped: %s; nothing written", e.what());
    return 1;
  }
  if (!std::isfinite(r.pso.best_cost)) {
    ROS_ERROR("pso_tuner: every run diverged (no finite cost); nothing written. Narrow the gain bounds.");
    return 1;
  }
  const core::Scenario tuned = core::TuningProblem(base_, reference_, gains_, objective_, 1).scenarioFor(r.best_gains);

  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S %z", std::localtime(&now));
  std::string searched;
  for (const auto& b : gains_)
    searched += (searched.empty() ? "" : ", ") + b.name + " [" + g(b.lower) + ", " + g(b.upper) + "]";
  std::string h;
  h += "# Controller gains tuned offline by pso_tuner (PSO, thesis eqs 4.26-4.31, Table 5.4).\n";
  h += "# Load with: roslaunch sowing_robot sim.launch gains:=THIS_FILE " + loadArgs() + "\n";
  h += "# date: " + std::string(date) + "\n";
  h += "# scenario: " + scenarioText() + "\n";
  h += "# cost: " + std::string(core::costTypeName(objective_.cost)) + " summed over x, y, theta";
  if (objective_.torque_weight > 0) h += " + " + g(objective_.torque_weight) + " * int (tau_R^2 + tau_L^2) dt";
  if (objective_.chattering_weight > 0) h += " + " + g(objective_.chattering_weight) + " * sum (|dtau_R| + |dtau_L|)";
  h += "\n";
  h += "# best_cost: " + yamlFloat(r.pso.best_cost) + "\n";
  h += "# initial_best_cost: " + yamlFloat(r.initial_best_cost) + "   (best of the random initial swarm)\n";
  h += "# best cost terms: tracking " + g(r.best.tracking) + ", effort " + g(r.best.effort) +
       " N^2.m^2.s, chattering " + g(r.best.chattering) + " N.m\n";
  h += "# pso: particles " + std::to_string(pso_.particles) + ", iterations " + std::to_string(pso_.iterations) +
       ", seed " + std::to_string(pso_.seed) + ", w " + g(pso_.w_max) + "..." + g(pso_.w_min) + ", c1 " + g(pso_.c1) +
       ", c2 " + g(pso_.c2) + ", velocity clamp " + g(pso_.max_velocity_fraction) + ", evaluations " +
       std::to_string(r.pso.evaluations) + ", " + std::to_string(r.threads) + " thread(s), " + fmt("%.2f", r.wall_s) +
       " s wall\n";
  h += "# searched: " + searched + "\n";
  h += "# Other parameters of " + base_.controllerName() + " were those of the base config.\n";
  const std::string e = writeGainsYaml(output_, h, tuned, gains_);
  if (!e.empty()) {
    ROS_ERROR("pso_tuner: %s", e.c_str());
    return 1;
  }
  std::string best;
  for (std::size_t d = 0; d < gains_.size(); ++d)
    best += (d ? ", " : "") + gains_[d].name + " " + fmt("%.5g", r.best_gains[d]);
  ROS_INFO(
      "pso_tuner: done in %.2f s (%ld evaluations, %ld of them stopped once they could not beat their "
      "particle's best, %d thread(s)): cost %.6g -> %.6g; %s",
      r.wall_s, r.pso.evaluations, r.evaluations_cut, r.threads, r.initial_best_cost, r.pso.best_cost, best.c_str());
  ROS_INFO("pso_tuner: wrote %s", output_.c_str());
  if (progress_pub_.getNumSubscribers() > 0) ros::WallDuration(0.3).sleep();  // let the last message go out
  return 0;
}

}  // namespace sowing_robot
