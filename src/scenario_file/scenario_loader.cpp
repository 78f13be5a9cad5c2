#include "sowing_robot/scenario_file/scenario_loader.h"

#include <sys/stat.h>

#include <dirent.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/control/kanayama.h"
#include "sowing_robot/core/control/pure_pursuit.h"
#include "sowing_robot/core/control/sliding_mode.h"
#include "sowing_robot/core/control/wheel_pid.h"
#include "sowing_robot/core/estimation/ekf.h"
#include "sowing_robot/core/evaluation/tuning.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/model/sensors.h"
#include "sowing_robot/core/model/soil_map.h"
#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/settings/node_settings.h"
#include "sowing_robot/core/simulation/runner.h"
#include "sowing_robot/scenario_file/scenario_sets.h"
#include "sowing_robot/scenario_file/yaml_reading.h"

namespace sowing_robot {
namespace scenario_file {

using core::ParamTable;
using core::ParamValue;
using namespace yaml_reading;

namespace {

/// [lo, hi] or a single value (fixed).
core::Uniform toUniform(const YAML::Node& n, const std::string& file, const std::string& key) {
  if (n.IsScalar()) {
    const double v = toDouble(n, file, key);
    return {v, v};
  }
  if (!n.IsSequence() || n.size() != 2) fail(file, key + " must be [lo, hi] or one number");
  return {toDouble(n[0], file, key + "[0]"), toDouble(n[1], file, key + "[1]")};
}

std::string stem(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = base.rfind(".yaml");
  return dot == std::string::npos ? base : base.substr(0, dot);
}

std::string directoryOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

bool fileExists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool directoryExists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

/// A scenario's or a profile's argument is a file path (contains '/' or ends with .yaml), else a name.
bool isPath(const std::string& name_or_path) {
  return name_or_path.find('/') != std::string::npos ||
         (name_or_path.size() > 5 && name_or_path.compare(name_or_path.size() - 5, 5, ".yaml") == 0);
}

/// A soil patch as the field file states it: a coefficient left out takes the traction block's value
/// (as plant_sim's loadSoilPatches does), resolved once that block is read.
struct PatchSpec {
  std::vector<Eigen::Vector2d> polygon;
  std::optional<double> mu_peak, mu_slide, rolling_resistance;
  double draft_factor = 1.0;  // the drill's draft against the field's (SoilPatch::draft_factor)
};

/// plant_sim/field/patches of a field config (config/field_thesis_wet.yaml): the keys plant_sim reads.
void loadPatches(const YAML::Node& plant_sim, const std::string& path, std::vector<PatchSpec>& out) {
  onlyKeys(plant_sim, {"field"}, path, "plant_sim/");
  const YAML::Node field = plant_sim["field"];
  onlyKeys(field, {"patches"}, path, "plant_sim/field/");
  const YAML::Node list = field["patches"];
  if (!list) return;
  if (!list.IsSequence())
    fail(path,
         "plant_sim/field/patches must be a list of {polygon, mu_peak, mu_slide, rolling_resistance, draft_factor}");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string name = "field/patches[" + std::to_string(i) + "]";
    const YAML::Node item = list[i];
    if (!item.IsMap())
      fail(path, name + " must be a map {polygon, mu_peak, mu_slide, rolling_resistance, draft_factor}");
    onlyKeys(item, {"polygon", "mu_peak", "mu_slide", "rolling_resistance", "draft_factor"}, path, name + "/");
    PatchSpec p;
    const YAML::Node poly = required(item, "polygon", path, name + "/");
    if (!poly.IsSequence()) fail(path, name + "/polygon must be a list of [x, y] vertices");
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const std::string v = name + "/polygon[" + std::to_string(k) + "]";
      if (!poly[k].IsSequence() || poly[k].size() != 2) fail(path, v + " must be a vertex [x, y] of two numbers");
      p.polygon.emplace_back(toDouble(poly[k][0], path, v), toDouble(poly[k][1], path, v));
    }
    if (item["mu_peak"]) p.mu_peak = toDouble(item["mu_peak"], path, name + "/mu_peak");
    if (item["mu_slide"]) p.mu_slide = toDouble(item["mu_slide"], path, name + "/mu_slide");
    if (item["rolling_resistance"])
      p.rolling_resistance = toDouble(item["rolling_resistance"], path, name + "/rolling_resistance");
    if (item["draft_factor"]) p.draft_factor = toDouble(item["draft_factor"], path, name + "/draft_factor");
    out.push_back(p);
  }
}

/// The patches with the traction block's values where a coefficient was left out, checked as plant_sim checks
/// them (SoilPatch::validate, and the patch's grip against the field's slip curve).
std::vector<core::SoilPatch> resolvePatches(const std::vector<PatchSpec>& specs, const core::TractionParams& ground,
                                            const std::string& path) {
  std::vector<core::SoilPatch> out;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const std::string name = "field/patches[" + std::to_string(i) + "]";
    core::SoilPatch patch;
    patch.polygon = specs[i].polygon;
    patch.mu_peak = specs[i].mu_peak.value_or(ground.mu_peak);
    patch.mu_slide = specs[i].mu_slide.value_or(ground.mu_slide);
    patch.rolling_resistance = specs[i].rolling_resistance.value_or(ground.rolling_resistance);
    patch.draft_factor = specs[i].draft_factor;
    std::string e = patch.validate(name);
    if (!e.empty()) fail(path, e);
    core::TractionParams t = ground;
    t.mu_peak = patch.mu_peak;
    t.mu_slide = patch.mu_slide;
    t.rolling_resistance = patch.rolling_resistance;
    e = t.validate();
    if (!e.empty()) fail(path, name + "/mu_peak: with the field's slip curve, " + e);
    out.push_back(patch);
  }
  return out;
}

/// A reference_generator config (config/field*.yaml): its field/ and potential/ keys through fieldTable(),
/// its obstacles; type must be field. Keys of the line reference (ReferenceGeneratorSettings) are allowed
/// and unused. plant_sim/field/patches (soil patches) go to `patches` (used with traction on).
void loadFieldConfig(const std::string& path, core::FieldParams& field, std::vector<core::Obstacle>& obstacles,
                     std::vector<PatchSpec>& patches) {
  const YAML::Node root = loadYaml(path);
  onlyKeys(root, {"reference_generator", "plant_sim"}, path, "");
  patches.clear();
  if (const YAML::Node ps = root["plant_sim"]) loadPatches(ps, path, patches);
  const YAML::Node rg = required(root, "reference_generator", path, "");
  if (!rg.IsMap()) fail(path, "reference_generator must be a mapping");
  std::vector<std::pair<std::string, YAML::Node>> keys, field_keys;
  flatten(rg, "", keys);
  for (const auto& kv : keys) {
    if (kv.first == "obstacles") continue;
    if (kv.first == "type") {
      if (kv.second.as<std::string>() != "field") fail(path, "reference_generator/type must be field");
      continue;
    }
    if (!core::fieldTable().find(kv.first) && core::ReferenceGeneratorSettings::table().find(kv.first)) continue;
    field_keys.push_back(kv);
  }
  applyKeys(core::fieldTable(), field_keys, field, path, "reference_generator/");
  obstacles.clear();
  if (const YAML::Node list = rg["obstacles"]) {
    if (!list.IsSequence()) fail(path, "reference_generator/obstacles must be a list");
    for (const auto& o : list) {
      onlyKeys(o, {"x", "y", "radius"}, path, "reference_generator/obstacles/");
      core::Obstacle ob;
      ob.x = toDouble(required(o, "x", path, "obstacles/"), path, "obstacles/x");
      ob.y = toDouble(required(o, "y", path, "obstacles/"), path, "obstacles/y");
      if (o["radius"]) ob.radius = toDouble(o["radius"], path, "obstacles/radius");
      const std::string e = ob.validate();
      if (!e.empty()) fail(path, "obstacle: " + e);
      obstacles.push_back(ob);
    }
  }
}

}  // namespace

const std::vector<std::string>& pendingModels() {
  // Empty since wet_soil and estimated_pose landed (core::availableModels()); a model announced but not
  // built yet goes here, and `requires:` refuses it with that reason.
  static const std::vector<std::string> pending{};
  return pending;
}

/// A profile's keys are the nodes' (it is a rosparam file too: sim.launch profile:= loads it as it stands):
/// each node's block that it may set, and the scenario block it goes to.
struct ProfileBlock {
  const char* node;
  const char* block;
};
constexpr ProfileBlock kProfileBlocks[] = {{"kinematic_controller", "limits"},
                                           {"plant_sim", "traction"},
                                           {"plant_sim", "motor"},
                                           {"plant_sim", "sensors"},
                                           {"torque_controller", "traction_control"},
                                           {"torque_controller", "hitch_control"},
                                           {"reference_generator", "speed_governor"},
                                           {"state_estimator", "estimator"}};

/// The profile's blocks merged into the scenario's root (see loadScenarioFile): each node's block key by key
/// into the scenario's block of that name (the profile's value wins), profile/feedback over the feedback.
void applyProfile(YAML::Node& root, const std::string& profile) {
  const YAML::Node prof = loadYaml(profile);
  std::set<std::string> nodes;  // the nodes of kProfileBlocks
  for (const ProfileBlock& b : kProfileBlocks) nodes.insert(b.node);
  std::set<std::string> top = nodes;
  top.insert("profile");
  onlyKeys(prof, top, profile, "");
  const YAML::Node own = required(prof, "profile", profile, "");
  onlyKeys(own, {"name", "description", "feedback"}, profile, "profile/");
  for (const std::string& node : nodes) {
    const YAML::Node blocks = prof[node];
    if (!blocks) continue;
    std::set<std::string> allowed;
    for (const ProfileBlock& b : kProfileBlocks)
      if (b.node == node) allowed.insert(b.block);
    onlyKeys(blocks, allowed, profile, node + "/");
    for (const std::string& block : allowed) {
      const YAML::Node from = blocks[block];
      if (!from) continue;
      if (!from.IsMap()) fail(profile, node + "/" + block + " must be a mapping");
      if (!root[block]) root[block] = YAML::Node(YAML::NodeType::Map);
      for (const auto& kv : from) root[block][kv.first.as<std::string>()] = YAML::Clone(kv.second);
    }
  }
  if (own["feedback"]) root["feedback"] = YAML::Clone(own["feedback"]);
}

/// The blocks that put a scenario on the estimated loop: applyLoopBlocks reads each of them.
constexpr const char* kLoopBlocks[] = {"traction", "sensors",          "estimator",      "feedback",     "motor",
                                       "limits",   "traction_control", "speed_governor", "hitch_control"};

/// The blocks of kLoopBlocks, each through the nodes' parameter table, onto `traction` and `cfg` (what they do not
/// set stays).
void applyLoopBlocks(const YAML::Node& root, const std::string& path, core::TractionParams& traction,
                     core::LoopConfig& cfg) {
  const YAML::Node sensors = root["sensors"], feedback = root["feedback"];
  if (const YAML::Node block = root["traction"])
    applyTableBlock(core::tractionTable(), block, traction, path, "traction");
  if (sensors) {
    if (!sensors.IsMap()) fail(path, "sensors must be a mapping");
    if (sensors["seed"])
      fail(path, "sensors/seed is drawn per run (draw 8 of the run's counter-based draws); leave it out");
    applyTableBlock(core::sensorsTable(), sensors, cfg.sensors, path, "sensors");
  }
  if (const YAML::Node block = root["estimator"])
    applyTableBlock(core::ekfTable(), block, cfg.estimator, path, "estimator");
  if (const YAML::Node block = root["motor"]) applyTableBlock(core::motorTable(), block, cfg.motor, path, "motor");
  if (const YAML::Node block = root["limits"])
    applyTableBlock(core::commandLimitsTable(), block, cfg.limits, path, "limits");
  if (const YAML::Node block = root["traction_control"])
    applyTableBlock(core::tractionControlTable(), block, cfg.traction_control, path, "traction_control");
  if (const YAML::Node block = root["speed_governor"])
    applyTableBlock(core::speedGovernorTable(), block, cfg.speed_governor, path, "speed_governor");
  if (const YAML::Node block = root["hitch_control"])
    applyTableBlock(core::hitchControlTable(), block, cfg.hitch_control, path, "hitch_control");
  if (feedback) {
    if (!feedback.IsScalar()) fail(path, "feedback must be one of ground_truth, odometry, fused");
    const std::string e = core::parseFeedback(feedback.Scalar(), cfg.feedback);
    if (!e.empty()) fail(path, e);
  }
}

core::BenchScenario loadScenarioFileImpl(const std::string& path, const std::string& profile) {
  YAML::Node root = loadYaml(path);
  if (!profile.empty()) applyProfile(root, profile);
  std::set<std::string> known = {
      "name",  "description", "track", "duration", "control_rate",    "start",    "line", "sine",
      "field", "plant",       "draws", "success",  "envelope_period", "requires", "set"};
  known.insert(std::begin(kLoopBlocks), std::end(kLoopBlocks));
  onlyKeys(root, known, path, "");
  core::BenchScenario b;
  std::vector<PatchSpec> patch_specs;
  b.name = required(root, "name", path, "").as<std::string>();
  if (b.name != stem(path)) fail(path, "name '" + b.name + "' must be the file's name ('" + stem(path) + "')");
  required(root, "description", path, "");
  // The evaluation set (docs/evaluation.md). A file without the key is validation: it may have been looked at
  // while designing; a scenario is test only when its file says so.
  if (const YAML::Node set = root["set"]) {
    if (!set.IsScalar()) fail(path, "set must be one of training, validation, test");
    const std::string e = checkScenarioSet(set.Scalar());
    if (!e.empty()) fail(path, e);
    b.set = set.Scalar();
  } else {
    b.set = "validation";
  }

  const std::string track = required(root, "track", path, "").as<std::string>();
  b.base.duration = toDouble(required(root, "duration", path, ""), path, "duration");
  const double rate = toDouble(required(root, "control_rate", path, ""), path, "control_rate");
  if (!(rate > 0.0)) fail(path, "control_rate must be > 0");
  b.base.control_period_ns = static_cast<std::int64_t>(1e9 / rate + 0.5);
  const YAML::Node start = required(root, "start", path, "");
  onlyKeys(start, {"x", "y", "theta"}, path, "start/");
  b.base.start = {toDouble(required(start, "x", path, "start/"), path, "start/x"),
                  toDouble(required(start, "y", path, "start/"), path, "start/y"),
                  toDouble(required(start, "theta", path, "start/"), path, "start/theta")};

  // The track and its block; the blocks of the other tracks are refused.
  const std::map<std::string, core::TrackKind> tracks{
      {"line", core::TrackKind::line}, {"field", core::TrackKind::field}, {"sine", core::TrackKind::sine}};
  const auto t = tracks.find(track);
  if (t == tracks.end()) fail(path, "track '" + track + "' is none of line, field, sine");
  b.track = t->second;
  for (const char* other : {"line", "sine", "field"})
    if (other != track && root[other])
      fail(path, std::string("block '") + other + "' does not apply to track " + track);
  const YAML::Node block = required(root, track, path, "");
  if (b.track == core::TrackKind::line) {
    onlyKeys(block, {"x0", "v_r", "y"}, path, "line/");
    b.line_x0 = toDouble(required(block, "x0", path, "line/"), path, "line/x0");
    b.line_v_r = toDouble(required(block, "v_r", path, "line/"), path, "line/v_r");
    b.line_y = toDouble(required(block, "y", path, "line/"), path, "line/y");
  } else if (b.track == core::TrackKind::sine) {
    onlyKeys(block, {"x0", "y0", "speed_x", "amplitude", "wavelength"}, path, "sine/");
    b.sine.x0 = toDouble(required(block, "x0", path, "sine/"), path, "sine/x0");
    b.sine.y0 = toDouble(required(block, "y0", path, "sine/"), path, "sine/y0");
    b.sine.speed_x = toDouble(required(block, "speed_x", path, "sine/"), path, "sine/speed_x");
    b.sine.amplitude = toDouble(required(block, "amplitude", path, "sine/"), path, "sine/amplitude");
    b.sine.wavelength = toDouble(required(block, "wavelength", path, "sine/"), path, "sine/wavelength");
  } else {
    onlyKeys(block, {"config", "finish_tolerance", "approach", "plan_detours", "follower"}, path, "field/");
    b.field = core::FieldRunSetup().field;  // with the footprint's radius, as run_scenario --field
    const std::string config = required(block, "config", path, "field/").as<std::string>();
    loadFieldConfig(config.front() == '/' ? config : directoryOf(path) + "/" + config, b.field, b.obstacles,
                    patch_specs);
    b.finish_tolerance = toDouble(required(block, "finish_tolerance", path, "field/"), path, "field/finish_tolerance");
    if (block["approach"]) b.field.approach = block["approach"].as<bool>();
    if (block["plan_detours"]) b.field.avoidance.plan_detours = block["plan_detours"].as<bool>();
    // Over the config's field/follower, through its table entry (the choices are named there only).
    if (const YAML::Node f = block["follower"])
      applyKeys(core::fieldTable(), {{"field/follower", f}}, b.field, path, "");
  }

  // Plant settings that are not drawn (the disturbance's frequency); the drawn ones are refused here.
  if (const YAML::Node plant = root["plant"]) {
    if (!plant.IsMap()) fail(path, "plant must be a mapping");
    std::vector<std::pair<std::string, YAML::Node>> keys;
    flatten(plant, "", keys);
    for (const auto& kv : keys)
      if (kv.first != "disturbance/frequency")
        fail(path, "plant/" + kv.first +
                       " is drawn per run or not a plant setting: only plant/disturbance/frequency "
                       "may be set here (the draws are under draws/)");
    applyKeys(core::disturbanceTable(), keys, b.base.disturbance, path, "plant/");
  }

  // What is drawn per run (every key stated, no defaults: the file says what the numbers mean).
  const YAML::Node draws = required(root, "draws", path, "");
  onlyKeys(draws,
           {"base_seed", "mass_scale", "inertia_scale", "amplitude", "phase", "noise_std", "start_dx", "start_dy",
            "start_dtheta"},
           path, "draws/");
  core::MonteCarloSpec& s = b.spec;
  const double seed = toDouble(required(draws, "base_seed", path, "draws/"), path, "draws/base_seed");
  if (!(seed >= 0.0) || seed != std::floor(seed)) fail(path, "draws/base_seed must be an integer >= 0");
  s.base_seed = static_cast<std::uint64_t>(seed);
  s.mass_scale = toUniform(required(draws, "mass_scale", path, "draws/"), path, "draws/mass_scale");
  s.inertia_scale = toUniform(required(draws, "inertia_scale", path, "draws/"), path, "draws/inertia_scale");
  s.amplitude = toUniform(required(draws, "amplitude", path, "draws/"), path, "draws/amplitude");
  s.phase = toUniform(required(draws, "phase", path, "draws/"), path, "draws/phase");
  s.noise_std = toDouble(required(draws, "noise_std", path, "draws/"), path, "draws/noise_std");
  s.start_dx = toUniform(required(draws, "start_dx", path, "draws/"), path, "draws/start_dx");
  s.start_dy = toUniform(required(draws, "start_dy", path, "draws/"), path, "draws/start_dy");
  s.start_dtheta = toUniform(required(draws, "start_dtheta", path, "draws/"), path, "draws/start_dtheta");

  const YAML::Node success = required(root, "success", path, "");
  onlyKeys(success,
           {"settle_time", "cross_track_threshold", "rule", "min_sown_share", "min_quality_of_feed",
            "max_seed_lateral_p95", "max_map_error_rms", "max_high_slip_share"},
           path, "success/");
  s.settle_time = toDouble(required(success, "settle_time", path, "success/"), path, "success/settle_time");
  s.cross_track_threshold =
      toDouble(required(success, "cross_track_threshold", path, "success/"), path, "success/cross_track_threshold");
  // A track with rows is judged by its seeds unless the file says otherwise; the sine track has no rows.
  s.rule = b.track == core::TrackKind::sine ? core::SuccessRule::tracking : core::SuccessRule::sown;
  if (success["rule"]) {
    const std::string rule = success["rule"].as<std::string>("");
    if (rule == "tracking")
      s.rule = core::SuccessRule::tracking;
    else if (rule == "sown" && b.track != core::TrackKind::sine)
      s.rule = core::SuccessRule::sown;
    else
      fail(path, "success/rule must be tracking or sown (sown needs rows: a line or field track), not '" + rule + "'");
  }
  const auto optional = [&](const char* key, double& value) {
    if (success[key]) value = toDouble(success[key], path, std::string("success/") + key);
  };
  optional("min_sown_share", s.min_sown_share);
  optional("min_quality_of_feed", s.min_quality_of_feed);
  optional("max_seed_lateral_p95", s.max_seed_lateral_p95);
  optional("max_map_error_rms", s.max_map_error_rms);
  optional("max_high_slip_share", s.max_high_slip_share);
  if (root["envelope_period"]) b.envelope_period = toDouble(root["envelope_period"], path, "envelope_period");

  // The loop's realism (BenchScenario::realism): the plant (traction:), the sensors (sensors:), the estimator
  // (estimator:) and what the controllers are fed (feedback:), each block through the nodes' parameter table with the
  // nodes' keys (traction/..., sensors/..., estimator/...), so a key, a range and an error read as plant_sim's and
  // state_estimator's. Any of them puts the scenario on the estimated loop (core/evaluation/estimated_bench.h).
  // The drive train's layers (motor:, limits:, traction_control:, speed_governor:, hitch_control:) likewise,
  // through their tables: any block of kLoopBlocks.
  if (std::any_of(std::begin(kLoopBlocks), std::end(kLoopBlocks),
                  [&root](const char* block) { return static_cast<bool>(root[block]); })) {
    core::LoopConfig cfg;
    core::TractionParams t;
    applyLoopBlocks(root, path, t, cfg);
    if (t.enabled) {
      cfg.traction = t;
      cfg.patches = resolvePatches(patch_specs, t, path);
    }
    b.realism = cfg;
  }  // (soil patches without traction are read and unused, as in the nodes)
  // `requires: [wet_soil, estimated_pose]`: the models the scenario needs, checked against what it switches on
  // (core::estimatedBenchCheck). A model announced but not built yet (pendingModels()) is refused with that reason.
  if (const YAML::Node req = root["requires"]) {
    if (!req.IsSequence()) fail(path, "requires must be a list of model names");
    for (const auto& m : req) {
      const std::string model = m.as<std::string>();
      const auto& pending = pendingModels();
      const auto& available = core::availableModels();
      if (std::find(pending.begin(), pending.end(), model) != pending.end())
        fail(path, "requires: model '" + model + "' is not available yet");
      if (std::find(available.begin(), available.end(), model) == available.end()) {
        std::string list;
        for (const auto& a : available) list += (list.empty() ? "" : ", ") + a;
        fail(path, "requires: unknown model '" + model + "' (available: " + list + ")");
      }
      b.requires_models.push_back(model);
    }
  }
  const std::string e = b.validate();
  if (!e.empty()) fail(path, e);
  return b;
}

ProfileFiles resolveProfile(const std::string& name_or_path, const std::string& source_dir) {
  if (isPath(name_or_path)) return {name_or_path, ""};
  // What sim.launch profile:=NAME loads: config/profiles/NAME.yaml, then config/tuned/NAME/OUTER+INNER.yaml.
  const std::string profiles = source_dir + "/config/profiles";
  const std::string file = profiles + "/" + name_or_path + ".yaml";
  if (!fileExists(file)) {
    std::string list;
    for (const auto& n : scenarioNames(profiles)) list += (list.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown profile '" + name_or_path + "' (available in " + profiles + ": " +
                                (list.empty() ? "none" : list) + ")");
  }
  const std::string gains = source_dir + "/config/tuned/" + name_or_path;
  return {file, directoryExists(gains) ? gains : ""};
}

void applyProfileTo(const std::string& profile, core::LoopConfig& cfg) {
  try {
    YAML::Node root(YAML::NodeType::Map);
    applyProfile(root, profile);  // exactly as on a scenario's blocks: here on none
    core::TractionParams t = cfg.traction.value_or(core::TractionParams());
    t.enabled = cfg.traction.has_value();
    applyLoopBlocks(root, profile, t, cfg);
    if (t.enabled)
      cfg.traction = t;
    else
      cfg.traction.reset();
  } catch (const YAML::Exception& e) {
    fail(profile, e.what());
  }
}

// yaml-cpp's own exceptions (a list where a word was expected, ...) become the one-line error too.
core::BenchScenario loadScenarioFile(const std::string& path, const std::string& profile) {
  try {
    return loadScenarioFileImpl(path, profile);
  } catch (const YAML::Exception& e) {
    fail(path, e.what());
  }
}

std::vector<std::string> scenarioNames(const std::string& dir) {
  std::vector<std::string> names;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (const dirent* entry = ::readdir(d)) {
      const std::string f = entry->d_name;
      if (f.size() > 5 && f.compare(f.size() - 5, 5, ".yaml") == 0) names.push_back(f.substr(0, f.size() - 5));
    }
    ::closedir(d);
  }
  std::sort(names.begin(), names.end());
  return names;
}

core::BenchScenario loadScenario(const std::string& name_or_path, const std::string& dir, const std::string& profile) {
  if (isPath(name_or_path)) return loadScenarioFile(name_or_path, profile);
  const std::string path = dir + "/" + name_or_path + ".yaml";
  if (!fileExists(path)) {
    std::string list;
    for (const auto& n : scenarioNames(dir)) list += (list.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown scenario '" + name_or_path + "' (known in " + dir + ": " + list + ")");
  }
  return loadScenarioFile(path, profile);
}

void applyTunedGainsImpl(const std::string& path, core::Scenario& sc) {
  const YAML::Node root = loadYaml(path);
  onlyKeys(root, {"kinematic_controller", "torque_controller"}, path, "");
  // The nodes' keys (what sim.launch gains:= loads): each node's parameters flat, Kanayama's beside pure
  // pursuit's and the sliding-mode controller's beside the PID's, all set through the tables
  // (core::setControllerParam: unknown keys and values out of range refused).
  const bool adaptive = sc.sliding.adaptive;
  for (const char* node : {"kinematic_controller", "torque_controller"}) {
    const YAML::Node g = root[node];
    if (!g) continue;
    if (!g.IsMap()) fail(path, std::string(node) + " must be a mapping");
    std::vector<std::pair<std::string, YAML::Node>> keys;
    flatten(g, "", keys);
    for (const auto& kv : keys) {
      const std::string error = core::setControllerParam(sc, node, kv.first, toParamValue(kv.second, path, kv.first));
      if (!error.empty()) fail(path, error);
    }
  }
  // The pair names the controller; a file tuned for the other mode is a mix-up, not a choice.
  if (sc.inner == core::InnerKind::sliding_mode && sc.sliding.adaptive != adaptive)
    fail(path, "torque_controller/mode is " + std::string(sc.sliding.adaptive ? "atsmc" : "tsmc") +
                   " but the pair is " + sc.controllerName());
  sc.sliding.adaptive = adaptive;
  const std::string e = sc.validate();
  if (!e.empty()) fail(path, e);
}

void applyTunedGains(const std::string& path, core::Scenario& sc) {
  try {
    applyTunedGainsImpl(path, sc);
  } catch (const YAML::Exception& e) {
    fail(path, e.what());
  }
}

std::string tunedGainsFile(const std::string& dir, const core::Scenario& sc) {
  const std::string path = dir + "/" + sc.controllerName() + ".yaml";
  return fileExists(path) ? path : "";
}

std::vector<TrainingRecord> trainingOf(const std::string& gains_path) {
  std::vector<TrainingRecord> out;
  std::ifstream f(gains_path);
  std::string line;
  while (std::getline(f, line)) {
    char name[256];
    long long runs = 0;
    unsigned long long seed = 0;
    if (std::sscanf(line.c_str(), "# training: %255s runs %lld base_seed %llu", name, &runs, &seed) == 3)
      out.push_back({name, runs, seed});
  }
  return out;
}

}  // namespace scenario_file
}  // namespace sowing_robot
