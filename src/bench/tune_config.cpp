#include "sowing_robot/bench/tune_config.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/control/controllers.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/settings/node_settings.h"

namespace sowing_robot {
namespace bench {

namespace {

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw std::invalid_argument(file + ": " + what);
}

void onlyKeys(const YAML::Node& map, const std::set<std::string>& known, const std::string& file,
              const std::string& where) {
  if (!map.IsMap()) fail(file, where + " must be a mapping");
  for (const auto& kv : map) {
    const std::string key = kv.first.as<std::string>();
    if (known.count(key)) continue;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    fail(file, "unknown key '" + where + key + "' (known: " + list + ")");
  }
}

double toDouble(const YAML::Node& n, const std::string& file, const std::string& key) {
  if (!n.IsScalar()) fail(file, key + " must be a number");
  const std::string t = n.Scalar();
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || *end != '\0' || !std::isfinite(v)) fail(file, key + " = '" + t + "' is not a finite number");
  return v;
}

/// A scalar as the parameter's type (that of `like`); `loose`: type unknown (bool, int, number or text).
core::ParamValue toValue(const YAML::Node& n, const core::ParamValue* like, const std::string& file,
                         const std::string& key) {
  if (!n.IsScalar()) fail(file, key + " must be a single value");
  const std::string t = n.Scalar();
  const bool want_bool = like && std::holds_alternative<bool>(*like);
  if (want_bool || !like) {
    if (t == "true" || t == "True") return true;
    if (t == "false" || t == "False") return false;
    if (want_bool) fail(file, key + " = '" + t + "' is not a bool");
  }
  char* end = nullptr;
  if (!like || std::holds_alternative<int>(*like)) {
    const long v = std::strtol(t.c_str(), &end, 10);
    if (!t.empty() && *end == '\0') return static_cast<int>(v);
    if (like) fail(file, key + " = '" + t + "' is not an integer");
  }
  if (!like || std::holds_alternative<double>(*like)) {
    const double v = std::strtod(t.c_str(), &end);
    if (!t.empty() && *end == '\0') {
      if (!std::isfinite(v)) fail(file, key + " = '" + t + "' is not a finite number");
      return v;
    }
    if (like) fail(file, key + " = '" + t + "' is not a number");
  }
  return t;
}

void flatten(const YAML::Node& map, const std::string& prefix, std::vector<std::pair<std::string, YAML::Node>>& out) {
  for (const auto& kv : map) {
    const std::string key = prefix + kv.first.as<std::string>();
    if (kv.second.IsMap())
      flatten(kv.second, key + "/", out);
    else
      out.emplace_back(key, kv.second);
  }
}

template <typename S>
void applyGroup(const core::ParamTable<S>& table, const YAML::Node& group, S& s, const std::string& file,
                const std::string& where, const std::set<std::string>& skip = {}) {
  if (!group.IsMap()) fail(file, where + " must be a mapping");
  std::vector<std::pair<std::string, YAML::Node>> keys;
  flatten(group, "", keys);
  for (const auto& kv : keys) {
    if (skip.count(kv.first)) continue;
    const auto* entry = table.find(kv.first);
    if (!entry) {
      std::string list;
      for (const auto& e : table.entries()) list += (list.empty() ? "" : ", ") + e.info.key;
      fail(file, "unknown key '" + where + kv.first + "' (known: " + list + ")");
    }
    const core::ParamValue v = toValue(kv.second, &entry->info.default_value, file, where + kv.first);
    const std::string error = entry->info.check(v, where);
    if (!error.empty()) fail(file, error);
    entry->set(s, v);
  }
}

std::string g(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

}  // namespace

std::string TuneConfig::scenarioText() const {
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

TuneConfig loadTuneConfig(const std::string& path) {
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
  if (!root.IsMap()) fail(path, "must be a mapping with pso_tuner: (and optionally scenario:)");
  onlyKeys(root, {"pso_tuner", "scenario"}, path, "");
  const YAML::Node pt = root["pso_tuner"];
  if (!pt) fail(path, "missing key 'pso_tuner' (config/pso.yaml's keys)");

  core::PsoTunerSettings settings;
  applyGroup(core::PsoTunerSettings::table(), pt, settings, path, "pso_tuner/", {"gains"});
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
  if (!settings.controller.empty()) {
    const std::string e =
        core::parseControllerPair(settings.controller, c.base.outer, c.base.inner, c.base.sliding.adaptive);
    if (!e.empty()) fail(path, "pso_tuner/controller: " + e);
  }

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
      applyGroup(core::disturbanceTable(), p, c.base.disturbance, path, "scenario/plant/");
    if (const YAML::Node ctl = sc["controllers"]) {
      onlyKeys(ctl, {"kinematic_controller", "torque_controller"}, path, "scenario/controllers/");
      for (const auto& node : ctl) {
        const std::string name = node.first.as<std::string>();
        if (!node.second.IsMap()) fail(path, "scenario/controllers/" + name + " must be a mapping");
        std::vector<std::pair<std::string, YAML::Node>> keys;
        flatten(node.second, "", keys);
        for (const auto& kv : keys) {
          const std::string e = core::setControllerParam(
              c.base, name, kv.first,
              toValue(kv.second, nullptr, path, "scenario/controllers/" + name + "/" + kv.first));
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
  for (const auto& b : c.gains) {
    c.pso.lower.push_back(b.lower);
    c.pso.upper.push_back(b.upper);
  }
  const std::string pe = c.pso.validate();
  if (!pe.empty()) fail(path, pe);
  return c;
}

}  // namespace bench
}  // namespace sowing_robot
