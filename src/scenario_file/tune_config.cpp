#include "sowing_robot/scenario_file/tune_config.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/control/controller_factory.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/settings/node_settings.h"
#include "sowing_robot/scenario_file/scenario_loader.h"
#include "sowing_robot/scenario_file/yaml_reading.h"

namespace sowing_robot {
namespace scenario_file {

using namespace yaml_reading;

namespace {

std::string g(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

std::string directoryOf(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

std::string relativeTo(const std::string& dir, const std::string& file) {
  return file.empty() || file[0] == '/' ? file : dir + "/" + file;
}

/// The robust: block: the objective and the training set, each scenario driven by c.base's pair and gains.
void loadRobust(const YAML::Node& r, const std::string& path, const std::string& source_dir, TuneConfig& c) {
  if (!r.IsMap())
    fail(path, "robust must be a mapping (aggregate, quantile, failure_penalty, max_slip_share, profile, training)");
  onlyKeys(r, {"aggregate", "quantile", "failure_penalty", "max_slip_share", "profile", "training"}, path, "robust/");
  if (const YAML::Node a = r["aggregate"]) {
    const std::string name = a.as<std::string>();
    if (!core::parseAggregate(name, c.robust.aggregate))
      fail(path, "robust/aggregate must be mean or quantile, not '" + name + "'");
  }
  if (r["quantile"]) c.robust.quantile = toDouble(r["quantile"], path, "robust/quantile");
  if (r["failure_penalty"]) c.robust.failure_penalty = toDouble(r["failure_penalty"], path, "robust/failure_penalty");
  if (r["max_slip_share"]) c.robust.max_slip_share = toDouble(r["max_slip_share"], path, "robust/max_slip_share");
  const std::string oe = c.robust.validate();
  if (!oe.empty()) fail(path, oe);
  const std::string dir = directoryOf(path);
  // robust/profile: a name as benchmark --profile takes it (config/profiles/NAME.yaml; its gains directory is
  // what this tuning writes, so it is not read), or a file relative to this file.
  std::string profile;
  if (const YAML::Node p = r["profile"]) {
    const std::string given = p.as<std::string>();
    ProfileFiles files;
    try {
      files = resolveProfile(given, source_dir);
    } catch (const std::invalid_argument& e) {
      fail(path, std::string("robust/profile: ") + e.what());
    }
    profile = files.file == given ? relativeTo(dir, given) : files.file;  // a path is taken as it is
  }
  const YAML::Node t = r["training"];
  if (!t || !t.IsSequence() || t.size() == 0)
    fail(path, "robust/training must be a non-empty list of {scenario: FILE, runs: N, base_seed: S}");
  for (std::size_t i = 0; i < t.size(); ++i) {
    const std::string at = "robust/training[" + std::to_string(i) + "]";
    onlyKeys(t[i], {"scenario", "runs", "base_seed"}, path, at + "/");
    for (const char* k : {"scenario", "runs", "base_seed"})
      if (!t[i][k]) fail(path, at + " has no '" + k + "'");
    const double runs = toDouble(t[i]["runs"], path, at + "/runs");
    const double seed = toDouble(t[i]["base_seed"], path, at + "/base_seed");
    if (!(runs >= 1 && runs <= 1e6 && runs == std::floor(runs))) fail(path, at + "/runs must be an integer >= 1");
    if (!(seed >= 0 && seed < 9e15 && seed == std::floor(seed))) fail(path, at + "/base_seed must be an integer >= 0");
    core::TrainingScenario ts;
    try {
      ts.bench =
          core::withController(loadScenarioFile(relativeTo(dir, t[i]["scenario"].as<std::string>()), profile), c.base);
    } catch (const std::exception& e) {
      fail(path, at + ": " + e.what());
    }
    // A test scenario is never looked at while designing (docs/evaluation.md): the tuner may not see it.
    if (ts.bench.set == "test")
      fail(path, at + " (" + ts.bench.name + "): a test scenario cannot be trained on (set: test; docs/evaluation.md)");
    ts.bench.spec.base_seed = static_cast<std::uint64_t>(seed);
    ts.runs = static_cast<std::int64_t>(runs);
    const std::string e = core::firstError({ts.bench.validate(), core::validateGainBounds(ts.bench.base, c.gains)});
    if (!e.empty()) fail(path, at + " (" + ts.bench.name + "): " + e);
    c.training.push_back(std::move(ts));
  }
}

}  // namespace

std::string TuneConfig::scenarioText() const {
  if (isRobust()) {
    std::string s =
        "robust: " +
        std::string(robust.aggregate == core::RobustObjective::Aggregate::mean ? "mean"
                                                                               : "quantile " + g(robust.quantile)) +
        " of the run costs, failure penalty " + g(robust.failure_penalty) +
        (robust.max_slip_share < 1.0 ? " (also past slip share " + g(robust.max_slip_share) + ")" : "") + ", " +
        base.controllerName() + "; training";
    for (const auto& t : training)
      s += " " + t.bench.name + " (runs 0-" + std::to_string(t.runs - 1) + ", base seed " +
           std::to_string(t.bench.spec.base_seed) + ")";
    return s;
  }
  const core::PlantDisturbance& d = base.disturbance;
  std::string s = g(base.duration) + " s at " + g(1e9 / static_cast<double>(base.control_period_ns)) + " Hz, " +
                  base.controllerName() + ", start (" + g(base.start.x) + ", " + g(base.start.y) + ", " +
                  g(base.start.theta) + "), line x = " + g(line_x0) + " + " + g(line_v_r) + " t, y = " + g(line_y) +
                  ", ";
  s += d.sinusoidal ? "sinusoidal disturbance A " + g(d.amplitude) + " N.m w " + g(d.frequency) + " rad/s"
                    : "no sinusoidal disturbance";
  s += ", mismatch mass x" + g(d.mass_scale) + " inertia x" + g(d.inertia_scale);
  s += ", noise std " + g(d.noise_std) + " N.m (seed " + std::to_string(d.seed) + ")";
  return s;
}

TuneConfig loadTuneConfig(const std::string& path, const std::string& controller, const std::string& source_dir) {
  TuneConfig c;
  {
    std::ifstream f(path, std::ios::binary);
    if (!f) fail(path, "cannot read the file");
    c.text.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  }
  YAML::Node root;
  try {
    root = YAML::Load(c.text);
  } catch (const YAML::Exception& e) {
    fail(path, std::string("not valid YAML: ") + e.what());
  }
  refuseRepeatedKeys(root, path);
  if (!root.IsMap()) fail(path, "must be a mapping with pso_tuner: (and optionally scenario:)");
  onlyKeys(root, {"pso_tuner", "scenario", "robust"}, path, "");
  const YAML::Node pt = root["pso_tuner"];
  if (!pt) fail(path, "missing key 'pso_tuner' (config/pso.yaml's keys)");

  core::PsoTunerSettings settings;
  applyGroup(core::PsoTunerSettings::table(), pt, settings, path, "pso_tuner", {"gains"});
  const std::string se = settings.validate();
  if (!se.empty()) fail(path, se);
  c.pso.particles = settings.particles;
  c.pso.iterations = settings.iterations;
  c.pso.seed = static_cast<std::uint64_t>(settings.seed);
  c.pso.threads = settings.threads;
  c.pso.max_velocity_fraction = settings.velocity_clamp;
  c.pso.w_max = settings.w_max;
  c.pso.w_min = settings.w_min;
  c.pso.c1 = settings.c1;
  c.pso.c2 = settings.c2;
  core::parseCostType(settings.cost, c.objective.cost);
  c.objective.torque_weight = settings.torque_weight;
  c.objective.chattering_weight = settings.chattering_weight;
  c.output = settings.output;
  c.base.duration = settings.duration;
  c.base.control_period_ns = static_cast<std::int64_t>(std::llround(1e9 / settings.control_rate));
  c.base.sliding.adaptive = settings.adaptive;
  if (!controller.empty()) settings.controller = controller;
  if (!settings.controller.empty()) {
    const std::string e =
        core::parseControllerPair(settings.controller, c.base.outer, c.base.inner, c.base.sliding.adaptive);
    if (!e.empty()) fail(path, (controller.empty() ? "pso_tuner/controller: " : "--controller: ") + e);
  }
  const YAML::Node robust = root["robust"];
  if (robust && root["scenario"])
    for (const char* k : {"start", "line", "plant"})
      if (root["scenario"][k])
        fail(path, std::string("scenario/") + k + " is not used with robust: (the training scenarios have their own)");

  if (const YAML::Node sc = root["scenario"]) {
    onlyKeys(sc, {"start", "line", "plant", "controllers"}, path, "scenario/");
    if (const YAML::Node s = sc["start"]) {
      onlyKeys(s, {"x", "y", "theta"}, path, "scenario/start/");
      if (s["x"]) c.base.start.x = toDouble(s["x"], path, "scenario/start/x");
      if (s["y"]) c.base.start.y = toDouble(s["y"], path, "scenario/start/y");
      if (s["theta"]) c.base.start.theta = toDouble(s["theta"], path, "scenario/start/theta");
    }
    if (const YAML::Node l = sc["line"]) {
      onlyKeys(l, {"x0", "v_r", "y"}, path, "scenario/line/");
      if (l["x0"]) c.line_x0 = toDouble(l["x0"], path, "scenario/line/x0");
      if (l["v_r"]) c.line_v_r = toDouble(l["v_r"], path, "scenario/line/v_r");
      if (l["y"]) c.line_y = toDouble(l["y"], path, "scenario/line/y");
    }
    if (const YAML::Node p = sc["plant"])
      applyGroup(core::disturbanceTable(), p, c.base.disturbance, path, "scenario/plant");
    if (const YAML::Node ctl = sc["controllers"]) {
      onlyKeys(ctl, {"kinematic_controller", "torque_controller"}, path, "scenario/controllers/");
      for (const auto& node : ctl) {
        const std::string name = node.first.as<std::string>();
        if (!node.second.IsMap()) fail(path, "scenario/controllers/" + name + " must be a mapping");
        std::vector<std::pair<std::string, YAML::Node>> keys;
        flatten(node.second, "", keys);
        for (const auto& kv : keys) {
          const std::string e = core::setControllerParam(
              c.base, name, kv.first, toParamValue(kv.second, path, "scenario/controllers/" + name + "/" + kv.first));
          if (!e.empty()) fail(path, "scenario/controllers: " + e);
        }
      }
    }
  }

  if (const YAML::Node gl = pt["gains"]) {
    if (!gl.IsSequence()) fail(path, "pso_tuner/gains must be a list of {name, lower, upper}");
    for (std::size_t i = 0; i < gl.size(); ++i) {
      const std::string at = "pso_tuner/gains[" + std::to_string(i) + "]";
      const YAML::Node e = gl[i];
      onlyKeys(e, {"name", "lower", "upper"}, path, at + "/");
      for (const char* k : {"name", "lower", "upper"})
        if (!e[k]) fail(path, at + " has no '" + k + "'");
      c.gains.push_back({e["name"].as<std::string>(), toDouble(e["lower"], path, at + "/lower"),
                         toDouble(e["upper"], path, at + "/upper")});
    }
  } else {
    c.gains = core::defaultGainBounds(c.base);
  }
  const std::string e =
      core::firstError({c.base.validate(), core::validateGainBounds(c.base, c.gains), c.objective.validate()});
  if (!e.empty()) fail(path, e);
  if (robust) loadRobust(robust, path, source_dir, c);
  for (const auto& b : c.gains) {
    c.pso.lower.push_back(b.lower);
    c.pso.upper.push_back(b.upper);
  }
  const std::string pe = c.pso.validate();
  if (!pe.empty()) fail(path, pe);
  return c;
}

}  // namespace scenario_file
}  // namespace sowing_robot
