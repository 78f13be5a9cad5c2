#include "sowing_robot/core/settings/param_catalog.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "sowing_robot/core/control/cmd_vel_input.h"
#include "sowing_robot/core/control/hitch_control.h"
#include "sowing_robot/core/control/traction_control.h"
#include "sowing_robot/core/estimation/ekf.h"
#include "sowing_robot/core/model/motor.h"
#include "sowing_robot/core/model/sensors.h"
#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/fleet_share.h"
#include "sowing_robot/core/planning/path_plan.h"
#include "sowing_robot/core/planning/speed_governor.h"
#include "sowing_robot/core/settings/node_settings.h"

namespace sowing_robot {
namespace core {

namespace {

/// A table cell: '|' would end it.
std::string cell(const std::string& text) {
  std::string out;
  for (const char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

template <typename S>
std::vector<ParamInfo> infos(const ParamTable<S>& table) {
  std::vector<ParamInfo> out;
  for (const auto& e : table.entries()) out.push_back(e.info);
  return out;
}

/// The tables' parameters one after the other.
template <typename... Tables>
std::vector<ParamInfo> concat(const Tables&... tables) {
  std::vector<ParamInfo> out;
  for (const std::vector<ParamInfo>& part : {infos(tables)...}) out.insert(out.end(), part.begin(), part.end());
  return out;
}

const CatalogSection* findSection(const std::string& ns) {
  for (const auto& s : parameterCatalog())
    if (s.ns == ns) return &s;
  return nullptr;
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t") - a + 1);
}

/// A YAML scalar as the type the parameter server would give it.
ParamValue parseScalar(const std::string& text) {
  if (text == "true" || text == "True") return true;
  if (text == "false" || text == "False") return false;
  if (text.size() >= 2 && (text.front() == '"' || text.front() == '\'') && text.back() == text.front())
    return text.substr(1, text.size() - 2);
  char* end = nullptr;
  const long i = std::strtol(text.c_str(), &end, 10);
  if (!text.empty() && *end == '\0') return static_cast<int>(i);
  const double d = std::strtod(text.c_str(), &end);
  if (!text.empty() && *end == '\0') return d;
  if (text == ".nan" || text == ".inf" || text == "-.inf")
    return text == ".nan" ? NAN : (text[0] == '-' ? -INFINITY : INFINITY);
  return text;
}

/// Column of the comment sign of a line (outside quotes), or npos.
std::size_t commentColumn(const std::string& line) {
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#' && (i == 0 || line[i - 1] == ' ' || line[i - 1] == '\t')) {
      return i;
    }
  }
  return std::string::npos;
}

constexpr std::size_t kCommentColumn = 28;  // where the config files' comments start

}  // namespace

const std::vector<CatalogSection>& parameterCatalog() {
  static const std::vector<CatalogSection> catalog = {
      {"run",
       "run-wide settings, set once per run (sim.launch) and read by every node; relative to the nodes' namespace",
       infos(RunSettings::table()),
       {}},
      {"plant_sim",
       "the plant: its two drivers' timing, the start pose, the disturbance and the mismatch, the opt-in "
       "wheel-soil traction (traction/, config/traction.yaml) with the field's soil patches (field/patches), "
       "sensors/: what the robot measures of itself, and the opt-in drive motors (motor/, core/model/motor.h: "
       "their data-sheet figures; the torque they apply goes out on applied_torque); the geometry and inertia "
       "come from the URDF (robot_description)",
       concat(PlantSimSettings::table(), tractionTable(), sensorsTable(), motorTable()),
       {"field/patches"}},
      {"kinematic_controller",
       "the outer loop, chosen by `outer`: Kanayama (eqs 4.1-4.2; kx, ky, ktheta live-tunable), pure pursuit or "
       "nav2's Regulated Pure Pursuit (nav2's parameter names; their numbers live-tunable, cfg/PurePursuit.cfg). "
       "Unmarked parameters are Kanayama's, "
       "[marked] ones the baselines'; the parameters of the controllers not selected are checked but inert",
       infos(KinematicControllerSettings::table()),
       {}},
      {"torque_controller",
       "the inner loop, chosen by `inner`: the integral terminal sliding-mode controller (eqs 4.7-4.22; `mode` "
       "atsmc or tsmc; gains live-tunable) or the wheel-velocity PID (gains live-tunable, cfg/WheelPid.cfg). "
       "Unmarked parameters are the "
       "sliding-mode controller's, [pid] ones the PID's; max_torque (the motor's limit) is both's; the parameters "
       "of the controller not selected are checked but inert. traction_control/ (opt-in, "
       "core/control/traction_control.h) caps a slipping wheel's torque after either of them; its state goes out "
       "on traction_control/state; hitch_control/ (opt-in, core/control/hitch_control.h, needs traction_control) "
       "raises the seed drill's tool on its grip verdict, sent with the torque (wheel_torque's tool_raised)",
       concat(TorqueControllerSettings::table(), tractionControlTable(), hitchControlTable()),
       {}},
      {"cmd_vel_limiter",
       "velocity mode (sim.launch input:=cmd_vel, config/cmd_vel.yaml, docs/interfaces.md): cmd_vel through the "
       "limiter to the inner loop; v and omega each follow the time-optimal profile within their bounds on value, "
       "acceleration and jerk (the same in reverse), and a command older than cmd_vel_timeout ramps them to zero",
       infos(CmdVelParams::table()),
       {}},
      {"reference_generator",
       "the reference: the thesis line, a field of rows through the potential field "
       "(field/ and potential/ keys and obstacles are read only with type field), or a given path "
       "(path/ keys, read only with type path; path/points: [[x, y], ...] in the odom frame [m]), or a field file "
       "planned by the coverage planner (coverage/ keys, config/coverage.yaml, read only with type coverage, which "
       "reads of field/ only row_speed, turn_speed and max_accel; fleet/: a fleet sharing the field, "
       "core/planning/fleet_share.h); speed_governor/ "
       "(opt-in, core/planning/speed_governor.h; needs torque_controller/traction_control/enabled) slows any of them "
       "while the wheels slip",
       concat(ReferenceGeneratorSettings::table(), fieldTable(), pathTable(), coverageTable(), fleetShareTable(),
              speedGovernorTable()),
       {"obstacles", "path/points"}},
      {"coverage_planner",
       "the coverage planner (core/planning/coverage_planner.h: planCoverage(), docs/coverage.md): headlands, swaths "
       "and one route over a field with voids. No node reads these keys yet (a node would refuse them): they are "
       "CoverageParams' keys for its callers, here so that their defaults and ranges are documented with the rest",
       infos(coverageTable()),
       {}},
      {"seed_drill",
       "the seed drill: spacing and scoring of the seeds against the plan",
       infos(SeedDrillSettings::table()),
       {}},
      {"state_estimator",
       "the EKF of feedback:=fused (core/estimation/ekf.h): pose and yaw-rate bias from the encoders, the yaw rate and "
       "the "
       "late position fix",
       concat(StateEstimatorSettings::table(), ekfTable()),
       {}},
      {"run_monitor", "the metric table at the end of a run", infos(RunMonitorSettings::table()), {}},
      {"fleet_monitor",
       "fleet.launch: owns /clock (the slowest robot's), compares the robots' positions by stamp and reports "
       "encounters closer than safety_distance; with yield, decides on every decision stamp which robots hold",
       infos(FleetMonitorSettings::table()),
       {}},
      {"pso_tuner",
       "offline PSO tuning (eqs 4.26-4.31, Table 5.4); the search box is the gains list",
       infos(PsoTunerSettings::table()),
       {"gains"}},
  };
  return catalog;
}

std::string yamlComment(const ParamInfo& info) {
  std::string c = info.meaning;
  if (!info.unit.empty()) c += " [" + info.unit + "]";
  return c + " " + info.rangeAndDefault();
}

std::string parametersMarkdown() {
  std::ostringstream md;
  md << "# Parameters\n\n"
        "Generated from the parameter tables (`include/sowing_robot/core/common/param_table.h`; each component's table "
        "sits next to its params struct) by `rosrun sowing_robot param_docs --markdown`; `test_param_docs` fails "
        "when this file, a `.cfg` or a comment in `config/*.yaml` is out of step with them. Keys are relative to "
        "the node's private namespace, except `run/`, which is relative to the nodes' own namespace. A key that "
        "the chosen configuration does not read is refused like an unknown one.\n";
  for (const CatalogSection& s : parameterCatalog()) {
    md << "\n## `" << s.ns << "`\n\n"
       << s.summary << ".\n\n| key | type | default | allowed | unit | meaning |\n"
       << "|---|---|---|---|---|---|\n";
    for (const ParamInfo& p : s.params) {
      std::string allowed;
      if (!p.choices.empty()) {
        for (const auto& c : p.choices) allowed += (allowed.empty() ? "" : " \\| ") + c;
      } else if (std::holds_alternative<int>(p.default_value) || std::holds_alternative<double>(p.default_value)) {
        allowed = p.limits.text();
      }
      md << "| `" << p.key << "` | " << typeName(p.default_value) << " | `" << formatValue(p.default_value) << "` | "
         << allowed << " | " << p.unit << " | " << cell(p.meaning) << (p.tunable ? " (PSO-tunable)" : "") << " |\n";
    }
    for (const auto& l : s.lists) md << "\n`" << l << "` is a list; see its comment in `config/`.\n";
  }
  return md.str();
}

std::string syncYamlComments(const std::string& text, const std::string& file, std::vector<std::string>& problems) {
  std::istringstream in(text);
  std::ostringstream out;
  std::vector<std::pair<std::size_t, std::string>> path;  // (indent, key) of the open mappings
  std::size_t continuation = std::string::npos;           // comment column of the parameter line just rewritten
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const std::string body = trim(line);
    const std::size_t indent = line.find_first_not_of(' ');
    if (!body.empty() && body[0] == '#' && continuation != std::string::npos && indent == continuation)
      continue;  // the old comment went on over several lines: the new one is a single line
    continuation = std::string::npos;
    std::size_t colon = body.find(':');
    const bool key_line = !body.empty() && (std::isalpha(static_cast<unsigned char>(body[0])) || body[0] == '_') &&
                          colon != std::string::npos;
    if (!key_line) {
      out << line << "\n";
      continue;
    }
    const std::string key = body.substr(0, colon);
    while (!path.empty() && path.back().first >= indent) path.pop_back();
    const std::size_t hash = commentColumn(line);
    const std::string value = trim(
        line.substr(indent + colon + 1, hash == std::string::npos ? std::string::npos : hash - indent - colon - 1));
    const CatalogSection* section = path.empty() ? nullptr : findSection(path.front().second);
    std::string rel;
    for (std::size_t i = 1; i < path.size(); ++i) rel += path[i].second + "/";
    rel += key;
    const bool list = section && std::find(section->lists.begin(), section->lists.end(), rel) != section->lists.end();
    if (value.empty() || value[0] == '[' || value[0] == '{' || !section || list) {
      if (value.empty()) path.emplace_back(indent, key);
      out << line << "\n";
      continue;
    }
    const ParamInfo* info = nullptr;
    for (const ParamInfo& p : section->params)
      if (p.key == rel) info = &p;
    const std::string where = file + ":" + std::to_string(number) + ": " + section->ns + "/" + rel;
    if (!info) {
      problems.push_back(where + " is no parameter of " + section->ns);
      out << line << "\n";
      continue;
    }
    ParamValue v = parseScalar(value);
    if (std::holds_alternative<double>(info->default_value) && std::holds_alternative<int>(v))
      v = static_cast<double>(std::get<int>(v));
    const std::string bad = info->check(v);
    if (!bad.empty()) problems.push_back(where + ": " + bad);
    std::string rewritten = line.substr(0, indent) + key + ": " + value;
    rewritten.resize(std::max(rewritten.size() + 1, kCommentColumn), ' ');
    out << rewritten << "# " << yamlComment(*info) << "\n";
    continuation = hash;
  }
  return out.str();
}

}  // namespace core
}  // namespace sowing_robot
