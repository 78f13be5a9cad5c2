// run_scenario: the thesis closed loop in-process (no ROS), for quick comparisons and benchmarks.
// Usage and options: kUsage below (run_scenario --help).
// Prints the Table 5.5/5.6 metrics as Markdown and the wall time per run. --field runs the thesis field
// (config/field_thesis.yaml: a 100 m row at y = 3, obstacles r 0.3 at x = 20, 50, 80; ATSMC, disturbance,
// 20 % mismatch, 110 s) measured on the body (the URDF's footprint) and prints clearance, contacts, peak
// yaw rate and v omega (from t = 12 s, after the approach from the start; and over the whole run), and
// the seeds on the rows and on the detours; --potential-only is the thesis potential field without the
// planned detours (the thesis's figures). The robot starts at --start (default the thesis's
// (-1, 0, 0)) and the target starts there too, on an approach to the row (field/approach);
// --no-approach starts the target at the row start instead (the figures before the approach).
// --traction runs the line with the traction plant (traction.h: peak friction MU, sliding 0.75 MU, the
// other traction/* defaults) instead of the no-slip one. With --field it runs the field so (Kanayama +
// ATSMC, or TSMC with --tsmc); --wet adds the wet patch of config/field_thesis_wet.yaml (mu_peak 0.2,
// mu_slide 0.15, rolling resistance 0.08 over x 43..58 m, y 1..5 m) and --draft N the tool's draft
// (traction/draft_force) while the tool is down; it prints the seeds' cross-track RMS / max and the
// largest slip.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "sowing_robot/cli/options.h"
#include "sowing_robot/cli/usage.h"
#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/simulation/field_run.h"
#include "sowing_robot/core/simulation/runner.h"

using namespace sowing_robot::core;

namespace {
const char* const kUsage =
    "usage: run_scenario [--tsmc] [--atsmc] [--disturbance] [--mismatch S] [--noise STD] [--duration T] [--rate HZ]\n"
    "                    [--switching NAME --width W] [--repeat N] [--yaml FILE]\n"
    "                    [--traction MU [--slip-stiffness K] [--rolling-resistance C]]\n"
    "       run_scenario --field [--potential-only | --path-follower] [--no-approach] [--start X Y THETA] [--rate HZ]\n"
    "                    [--tsmc] [--traction MU [--wet] [--draft N]]\n"
    "The thesis closed loop in-process (no ROS): the Table 5.5/5.6 metrics as Markdown and the wall time per run.\n\n"
    "Options (line):\n"
    "  --atsmc, --tsmc          the modes run, in order (default both)\n"
    "  --disturbance            the sinusoidal wheel disturbance\n"
    "  --mismatch S             plant mass and inertia x S\n"
    "  --noise STD              Gaussian torque noise [N.m]\n"
    "  --duration T, --rate HZ  run length [s] and control rate\n"
    "  --switching NAME         switching function; --width W its boundary layer\n"
    "  --repeat N               runs per mode (wall time per run)\n"
    "  --yaml FILE              the metrics of the last mode as YAML\n"
    "  --traction MU            the traction plant (peak friction MU, sliding 0.75 MU); --slip-stiffness K,\n"
    "                           --rolling-resistance C\n"
    "Options (--field: the thesis field, 100 m row, obstacles at x = 20, 50, 80, measured on the body):\n"
    "  --potential-only         the thesis potential field without the planned detours\n"
    "  --no-approach            the target starts at the row start\n"
    "  --path-follower          field/follower path: the field's path through the path follower of input:=path\n"
    "  --start X Y THETA        the robot's start (default -1 0 0)\n"
    "  --traction MU            with --wet (the wet patch of config/field_thesis_wet.yaml), --draft N (tool draft)\n"
    "  -h, --help               this text\n";

/// The command line, as given (defaults where an option is absent).
struct Options {
  std::vector<bool> modes;  // the sliding modes run, in order: true ATSMC, false TSMC
  bool field = false, potential_only = false, approach = true, wet = false, path_follower = false;
  Pose2D start = Scenario().start;
  Scenario sc;
  int repeat = 1;
  std::string yaml;
  TractionParams traction;  // enabled by --traction
};

/// Reads the options into `o`; false, with the error line printed and `exit_code` set, on a bad one.
bool parseOptions(int argc, char** argv, Options& o, int& exit_code) {
  namespace cli = sowing_robot::cli;
  namespace po = cli::po;
  auto flag = [] { return po::value<std::vector<std::string>>()->zero_tokens()->composing(); };
  auto number = [] { return po::value<std::string>(); };
  po::options_description options;
  options.add_options()("field", flag())("potential-only", flag())("no-approach", flag())("path-follower", flag())(
      "tsmc", flag())("atsmc", flag())("disturbance", flag())("wet", flag())(
      "start", po::value<std::vector<std::string>>()->multitoken())("mismatch", number())("noise", number())(
      "duration", number())("rate", number())("width", number())("repeat", number())("traction", number())(
      "draft", number())("slip-stiffness", number())("rolling-resistance", number())("yaml", po::value(&o.yaml))(
      "switching", po::value<std::string>());
  cli::Parse parse{"run_scenario", options, {}, [](const std::string& a) {
                     return (a == "--start" ? a + " X" : a) + " needs a value";
                   }};
  parse.fixed_arity = {{"start", 3}};
  po::variables_map vm;
  std::vector<std::string> order;
  std::string error = cli::parseOptions(argc, argv, parse, vm, &order);
  if (error.empty() && vm.count("start")) {
    const auto& xyt = vm["start"].as<std::vector<std::string>>();
    if (xyt.size() < 3) error = std::string(xyt.size() == 1 ? "--start Y" : "--start THETA") + " needs a value";
    if (xyt.size() > 3) error = "unknown option '" + xyt[3] + "' (see run_scenario --help)";
    if (error.empty())
      o.start = {std::strtod(xyt[0].c_str(), nullptr), std::strtod(xyt[1].c_str(), nullptr),
                 std::strtod(xyt[2].c_str(), nullptr)};
  }
  if (error.empty() && vm.count("switching") &&
      !SwitchFunction::parse(vm["switching"].as<std::string>().c_str(), o.sc.sliding.switching.type))
    error = "unknown switching '" + vm["switching"].as<std::string>() + "'";
  if (!error.empty()) {
    std::fprintf(stderr, "run_scenario: %s\n", error.c_str());
    exit_code = cli::kUsageExit;
    return false;
  }
  for (const std::string& key : order) {  // the modes in the order given
    if (key == "tsmc" || key == "atsmc") o.modes.push_back(key == "atsmc");
  }
  o.field = vm.count("field") > 0;
  o.potential_only = vm.count("potential-only") > 0;
  o.approach = vm.count("no-approach") == 0;
  o.path_follower = vm.count("path-follower") > 0;
  o.wet = vm.count("wet") > 0;
  if (vm.count("disturbance")) o.sc.disturbance.sinusoidal = true;
  // The numbers as strtod reads them (no check: the scenario's validate() and the traction's say what is wrong).
  auto value = [&vm](const char* key, auto set) {
    if (vm.count(key)) set(std::strtod(vm[key].as<std::string>().c_str(), nullptr));
  };
  value("mismatch", [&](double v) { o.sc.disturbance.mass_scale = o.sc.disturbance.inertia_scale = v; });
  value("noise", [&](double v) { o.sc.disturbance.noise_std = v; });
  value("duration", [&](double v) { o.sc.duration = v; });
  value("rate", [&](double v) { o.sc.control_period_ns = static_cast<std::int64_t>(1e9 / v + 0.5); });
  value("width", [&](double v) { o.sc.sliding.switching.width = v; });
  value("repeat", [&](double v) { o.repeat = static_cast<int>(v); });
  value("traction", [&](double v) {
    o.traction.enabled = true;
    o.traction.mu_peak = v;
    o.traction.mu_slide = 0.75 * v;
  });
  value("draft", [&](double v) { o.traction.draft_force = v; });
  value("slip-stiffness", [&](double v) { o.traction.slip_stiffness = v; });
  value("rolling-resistance", [&](double v) { o.traction.rolling_resistance = v; });
  return true;
}

/// Why --field's options do not go together ("" when they do).
std::string fieldOptionsError(const Options& o) {
  if (o.potential_only && o.path_follower)
    return "--potential-only and --path-follower exclude each other (the path follower has no repulsion: it needs "
           "the planned detours)";
  const std::string err = o.traction.enabled ? o.traction.validate() : "";
  if (!err.empty() || ((o.wet || o.traction.draft_force > 0.0) && !o.traction.enabled))
    return err.empty() ? "--wet and --draft need --traction MU" : err;
  return "";
}

/// The thesis field (config/field_thesis.yaml) as the options set it up, before its check and the
/// approach's extra time.
FieldRunSetup thesisFieldSetup(const Options& o) {
  FieldRunSetup s;
  s.scenario.sliding.adaptive = o.modes.empty() || o.modes.back();
  if (o.traction.enabled) {
    s.traction = o.traction;
    if (o.wet) {
      SoilPatch patch;  // config/field_thesis_wet.yaml
      patch.polygon = {{43.0, 1.0}, {58.0, 1.0}, {58.0, 5.0}, {43.0, 5.0}};
      patch.mu_peak = 0.2;
      patch.mu_slide = 0.15;
      patch.rolling_resistance = 0.08;
      s.patches = {patch};
    }
  }
  s.scenario.duration = 110.0;
  if (o.sc.control_period_ns > 0) s.scenario.control_period_ns = o.sc.control_period_ns;
  s.scenario.start = o.start;
  s.field.approach = o.approach;
  s.field.start_pose = o.start;  // what the node takes from plant_sim's start/{x, y, theta}
  s.field.rows = 1;
  s.field.row_length = 100.0;
  s.field.start_x = 0.0;
  s.field.start_y = 3.0;
  s.field.potential.beta = 4.0;  // config/field_thesis.yaml (alpha 4, influence 0.5, gain 5, ratio 1 are the defaults)
  s.field.avoidance.plan_detours = !o.potential_only;
  if (o.path_follower) s.field.follower = FieldFollower::kPath;
  s.obstacles = {{20.0, 3.0, 0.3}, {50.0, 3.0, 0.3}, {80.0, 3.0, 0.3}};
  return s;
}

/// The field run's table and lines: `r` measured from t = 12 s, `w` over the whole run.
void printFieldReport(const Options& o, const FieldRunSetup& s, const FieldRunReport& r, const FieldRunReport& w,
                      double wall) {
  std::printf("thesis field, %s%s%s (%.0f ms wall), start (%.2f, %.2f, %.3f), footprint circumscribed radius %.3f m:\n",
              s.scenario.sliding.adaptive ? "" : "TSMC, ",
              o.potential_only  ? "potential field only (thesis)"
              : o.path_follower ? "planned detours through the path follower"
                                : "planned detours",
              o.potential_only ? "" : (o.approach ? ", approach from the start" : ", no approach"), 1e3 * wall,
              o.start.x, o.start.y, o.start.theta, s.footprint.circumscribedRadius());
  std::printf(
      "| body clearance | contacts | peak yaw rate | peak v*omega | peak yaw rate / v*omega, whole run | "
      "seeds on rows: count, max, RMS | detour seeds: count, max | end |\n|---|---|---|---|---|---|---|---|\n");
  std::printf(
      "| %.3f m | %zu | %.2f rad/s | %.2f m/s^2 | %.2f rad/s / %.2f m/s^2 | %zu, %.2f mm, %.2f mm | %zu, %.3f m | "
      "(%.2f, %.2f) |\n",
      r.min_clearance, r.contacts, r.peak_yaw_rate, r.peak_lateral, w.peak_yaw_rate, w.peak_lateral, r.rows.count,
      1e3 * r.rows.max, 1e3 * r.rows.rms, r.detours.count, r.detours.max, r.end.x(), r.end.y());
  for (const ContactEvent& e : r.events)
    std::printf("contact: obstacle %zu, t = %.3f .. %.3f s, max depth %.3f m\n", e.obstacle, e.start, e.end,
                e.max_depth);
  std::printf(
      "reference (from t = 12 s): peak yaw rate %.2f rad/s, v*omega %.2f m/s^2, curvature %.2f 1/m; whole run: "
      "%.2f rad/s, %.2f m/s^2, %.2f 1/m; status %s%s%s%s%s\n",
      r.peak_ref_yaw_rate, r.peak_ref_lateral, r.peak_ref_curvature, w.peak_ref_yaw_rate, w.peak_ref_lateral,
      w.peak_ref_curvature, AvoidanceStatus::name(r.status.code), r.status.reason.empty() ? "" : ": ",
      r.status.reason.c_str(), r.status.within_bounds ? "" : "; bounds not held: ", r.status.bounds_note.c_str());
  if (o.traction.enabled)
    std::printf(
        "traction: mu_peak %g, %zu soil patch(es), draft %g N (tool down %.1f s); max |slip ratio| %.3f; "
        "seeds on rows: cross-track RMS %.2f mm, max %.2f mm; %ld saturated periods%s\n",
        o.traction.mu_peak, s.patches.size(), o.traction.draft_force, r.tool_down_time, r.max_slip, 1e3 * r.rows.rms,
        1e3 * r.rows.max, r.saturated, r.diverged ? ", DIVERGED" : "");
}

/// The thesis field on the body; returns the exit code.
int runThesisField(const Options& o) {
  FieldRunSetup s = thesisFieldSetup(o);
  const std::string err = s.field.validate();
  if (!err.empty()) {
    std::fprintf(stderr, "run_scenario: %s\n", err.c_str());
    return 2;
  }
  // The approach makes the path longer than the straight row (thesis: by 2.46 s): the run is longer by as
  // much, so it ends at the same point of the row as without it.
  s.scenario.duration += approachExtraTime(s);
  FieldRunSetup whole = s;
  s.peaks_from = 12.0;
  const auto t0 = std::chrono::steady_clock::now();
  const FieldRunReport r = runField(s);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const FieldRunReport w = runField(whole);
  printFieldReport(o, s, r, w, wall);
  return r.diverged ? 1 : 0;
}

/// One mode's line runs: the last run, its largest slip (traction plant) and the wall time per run.
struct LineRuns {
  RunResult run;
  double max_slip = 0.0;
  double seconds_per_run = 0.0;
};

LineRuns runLine(const Scenario& sc, const TractionParams& traction, int repeat) {
  LineReference ref;
  LineRuns out;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < repeat; ++k) {
    if (traction.enabled) {
      LoopConfig plant;  // the traction plant, fed the truth
      plant.traction = traction;
      const LoopResult er = runClosedLoop(sc, plant, ref);
      out.run = er.run;
      out.max_slip = er.max_abs_slip;
    } else {
      out.run = runClosedLoop(sc, ref);
    }
  }
  out.seconds_per_run = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / repeat;
  return out;
}

/// The line in each mode asked for (default ATSMC, then TSMC): a line per mode, then the metrics table;
/// returns the exit code.
int runLineModes(const Options& o) {
  const std::vector<bool> modes = o.modes.empty() ? std::vector<bool>{true, false} : o.modes;
  Scenario sc = o.sc;
  std::vector<std::string> names;
  std::vector<std::array<AxisMetrics, AXIS_COUNT>> results;
  for (bool adaptive : modes) {
    sc.sliding.adaptive = adaptive;
    const std::string err = firstError({sc.validate(), o.traction.enabled ? o.traction.validate() : ""});
    if (!err.empty()) {
      std::fprintf(stderr, "run_scenario: %s\n", err.c_str());
      return 2;
    }
    const LineRuns runs = runLine(sc, o.traction, o.repeat);
    const RunResult& r = runs.run;
    const double s = runs.seconds_per_run;
    std::printf(
        "%s: %.3f ms wall per %.1f s run (%.2f M steps/s), final (x %.4f, y %.4f, theta %.5f), "
        "%ld saturated periods%s\n",
        adaptive ? "ATSMC" : "TSMC", 1e3 * s, sc.duration, (sc.steps() + 1) / s / 1e6, r.final_state[X],
        r.final_state[Y], r.final_state[THETA], static_cast<long>(r.saturated_steps), r.diverged ? ", DIVERGED" : "");
    if (o.traction.enabled)
      std::printf("  traction: mu_peak %g, max |slip ratio| %.3f\n", o.traction.mu_peak, runs.max_slip);
    names.push_back(adaptive ? "atsmc" : "tsmc");
    results.push_back(r.metrics);
    if (!o.yaml.empty() && !writeMetricsYaml(o.yaml, names.back(), r.metrics)) {
      std::fprintf(stderr, "run_scenario: cannot write %s\n", o.yaml.c_str());
      return 2;
    }
  }
  std::printf("\n%s", metricsTable(names, results).c_str());
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  Options o;
  sowing_robot::cli::exitOnHelp(argc, argv, kUsage);
  int exit_code = 0;
  if (!parseOptions(argc, argv, o, exit_code)) return exit_code;
  if (!o.field) return runLineModes(o);
  const std::string err = fieldOptionsError(o);
  if (!err.empty()) {
    std::fprintf(stderr, "run_scenario: %s\n", err.c_str());
    return 2;
  }
  return runThesisField(o);
}
