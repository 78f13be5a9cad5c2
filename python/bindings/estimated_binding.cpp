// sowing_robot.core.run_estimated: core::runClosedLoop (core/simulation/runner.h) from Python: the closed
// loop with the traction plant, the seeded sensors and the controllers fed the truth, the encoder odometry or the EKF's
// estimate, scored on the truth. Its blocks take the nodes' keys (plant_sim's traction/ and sensors/, state_estimator's
// estimator/), checked by the same tables, so a key or a range reads as the node's. profile= applies a profile file
// (config/profiles/NAME.yaml) through the benchmark's own reading of it (scenario_file::applyProfileTo), on top of the
// call's blocks.
#include <stdexcept>
#include <string>
#include <vector>

#include "core_bindings.h"
#include "sowing_robot/core/evaluation/bench_row.h"
#include "sowing_robot/core/evaluation/run_metrics.h"
#include "sowing_robot/core/evaluation/seed_metrics.h"
#include "sowing_robot/core/simulation/runner.h"
#include "sowing_robot/core/simulation/seed_recorder.h"
#include "sowing_robot/scenario_file/scenario_loader.h"

namespace py_core {
namespace {

/// A dict of a table's keys below `prefix` (nested dicts join with '/': {"fix": {"sigma": 0.05}} is
/// prefix + "fix/sigma"), each checked against the table's type and range.
template <typename S>
void applyTableDict(const ParamTable<S>& table, S& s, const std::string& prefix, const py::handle& d,
                    const std::string& what) {
  if (!py::isinstance<py::dict>(d)) throw py::type_error(what + " must be a dict {key: value}");
  for (const auto& kv : d.cast<py::dict>()) {
    const std::string key = prefix + kv.first.cast<std::string>();
    if (py::isinstance<py::dict>(kv.second)) {
      applyTableDict(table, s, key + "/", kv.second, what);
      continue;
    }
    const ParamEntry<S>* e = table.find(key);
    if (!e) throw py::value_error(what + ": " + key + " is no parameter of this block");
    ParamValue v = toParamValue(kv.second, key);
    // An integer where the table wants a double (2 for 2.0) is that double.
    if (std::holds_alternative<int>(v) && std::holds_alternative<double>(e->info.default_value))
      v = static_cast<double>(std::get<int>(v));
    const std::string error = e->info.check(v, "");
    if (!error.empty()) throw py::value_error(what + ": " + error);
    e->set(s, v);
  }
}

/// {"polygon": [[x, y], ...], "mu_peak": .., "mu_slide": .., "rolling_resistance": .., "draft_factor": ..}; a
/// coefficient left out is the traction block's (as plant_sim reads field/patches).
SoilPatch patchOf(const py::handle& item, const TractionParams& ground, std::size_t i) {
  const std::string name = "patches[" + std::to_string(i) + "]";
  if (!py::isinstance<py::dict>(item)) throw py::type_error(name + " must be a dict with a polygon");
  const py::dict d = item.cast<py::dict>();
  SoilPatch p;
  p.mu_peak = ground.mu_peak;
  p.mu_slide = ground.mu_slide;
  p.rolling_resistance = ground.rolling_resistance;
  for (const auto& kv : d) {
    const std::string key = kv.first.cast<std::string>();
    if (key == "polygon") {
      for (const auto& v : kv.second) {
        const auto xy = v.cast<std::vector<double>>();
        if (xy.size() != 2) throw py::value_error(name + "/polygon: one [x, y] per vertex");
        p.polygon.emplace_back(xy[0], xy[1]);
      }
    } else if (key == "mu_peak") {
      p.mu_peak = kv.second.cast<double>();
    } else if (key == "mu_slide") {
      p.mu_slide = kv.second.cast<double>();
    } else if (key == "rolling_resistance") {
      p.rolling_resistance = kv.second.cast<double>();
    } else if (key == "draft_factor") {
      p.draft_factor = kv.second.cast<double>();
    } else {
      throw py::value_error(name + ": unknown key '" + key +
                            "' (polygon, mu_peak, mu_slide, rolling_resistance, draft_factor)");
    }
  }
  const std::string e = p.validate(name);
  if (!e.empty()) throw py::value_error(e);
  return p;
}

/// The loop's trace (Trace's columns) and what the controllers were fed, the slip and the tool.
struct EstimatedTrace {
  Trace loop;
  std::vector<std::string> names = {"fed_x",      "fed_y",     "fed_theta", "fed_v",     "fed_omega",
                                    "slip_right", "slip_left", "tool_down", "tool_depth"};
  std::vector<std::vector<double>> columns = std::vector<std::vector<double>>(names.size());

  void reserve(std::size_t n) {
    loop.reserve(n);
    for (auto& c : columns) c.reserve(n);
  }
  void add(const EstimatedSample& s) {
    loop.add(*s.loop);
    const double row[] = {s.fed.x,     s.fed.y,      s.fed.theta, s.fed_v,
                          s.fed_omega, s.slip_right, s.slip_left, s.tool_down ? 1.0 : 0.0,
                          s.tool_depth};
    for (std::size_t i = 0; i < columns.size(); ++i) columns[i].push_back(row[i]);
  }
  py::dict toDict() const {
    py::dict d = loop.toDict();
    for (std::size_t i = 0; i < names.size(); ++i) d[names[i].c_str()] = toArray(columns[i]);
    return d;
  }
};

py::dict fixCounts(const FixCounts& c, long lost_from_queue) {
  py::dict d;
  d["applied"] = c.applied;
  d["reanchored"] = c.reanchored;
  d["slip_onsets"] = c.slip_onsets;
  d["gated"] = c.gated;
  d["too_old"] = c.too_old;
  d["future"] = c.future;
  d["invalid"] = c.invalid;
  d["lost_from_queue"] = lost_from_queue;
  return d;
}

/// The seed record as columns (lists): t, x, y (where each seed fell), believed_x, believed_y, row, depth, detour.
py::dict seedsDict(const std::vector<Seed>& seeds) {
  std::vector<double> t, x, y, bx, by, depth;
  std::vector<int> row;
  std::vector<bool> detour;
  for (const Seed& s : seeds) {
    t.push_back(s.t);
    x.push_back(s.truth.x());
    y.push_back(s.truth.y());
    bx.push_back(s.believed.x());
    by.push_back(s.believed.y());
    row.push_back(s.row);
    depth.push_back(s.depth);
    detour.push_back(s.detour);
  }
  py::dict d;
  d["t"] = t;
  d["x"] = x;
  d["y"] = y;
  d["believed_x"] = bx;
  d["believed_y"] = by;
  d["row"] = row;
  d["depth"] = depth;
  d["detour"] = detour;
  return d;
}

/// The seed figures under the metric registry's names (run_metrics.h: its seed_figure entries), as runs.csv has them.
py::dict seedFiguresDict(const SeedFigures& f) {
  RunRow row;
  row.seed_figures = f;
  py::dict d;
  for (const RunMetric& m : runMetrics())
    if (m.seed_figure) d[m.name.c_str()] = m.get(row);
  return d;
}

py::dict runEstimatedPy(const std::string& controller, const py::object& params, const py::object& gains,
                        const std::string& feedback, const py::object& traction, const py::object& patches,
                        const py::object& sensors, const py::object& estimator, const py::object& motor,
                        const py::object& limits, const py::object& traction_control, const py::object& speed_governor,
                        const py::object& hitch_control, const py::object& profile, double duration,
                        std::int64_t control_period_ns, bool disturbance, double mass_scale, double inertia_scale,
                        double noise_std, std::uint64_t seed, const std::array<double, 3>& start,
                        double disturbance_phase, const std::optional<std::array<double, 3>>& line, bool keep_samples,
                        bool trace) {
  const Scenario sc = buildScenario(
      controller, params, gains,
      {duration, control_period_ns, disturbance, mass_scale, inertia_scale, noise_std, seed, start, disturbance_phase});
  LoopConfig cfg;
  std::string e = parseFeedback(feedback, cfg.feedback);
  if (!e.empty()) throw py::value_error(e);
  if (!traction.is_none()) {
    TractionParams t;
    if (!py::isinstance<py::bool_>(traction))
      applyTableDict(tractionTable(), t, "traction/", traction, "traction");
    else if (!traction.cast<bool>())
      throw py::value_error("traction: None (or leave it out) for the no-slip plant, True or a dict for traction");
    cfg.traction = t;
  }
  if (!sensors.is_none()) applyTableDict(sensorsTable(), cfg.sensors, "sensors/", sensors, "sensors");
  if (!estimator.is_none()) applyTableDict(ekfTable(), cfg.estimator, "estimator/", estimator, "estimator");
  if (!motor.is_none()) applyTableDict(motorTable(), cfg.motor, "motor/", motor, "motor");
  if (!limits.is_none()) applyTableDict(commandLimitsTable(), cfg.limits, "limits/", limits, "limits");
  if (!traction_control.is_none())
    applyTableDict(tractionControlTable(), cfg.traction_control, "traction_control/", traction_control,
                   "traction_control");
  if (!speed_governor.is_none())
    applyTableDict(speedGovernorTable(), cfg.speed_governor, "speed_governor/", speed_governor, "speed_governor");
  if (!hitch_control.is_none())
    applyTableDict(hitchControlTable(), cfg.hitch_control, "hitch_control/", hitch_control, "hitch_control");
  std::string profile_name;
  if (!profile.is_none()) {
    if (!py::isinstance<py::str>(profile)) throw py::type_error("profile must be a name (\"field\") or a file path");
    profile_name = profile.cast<std::string>();
    try {  // the benchmark's reading of the file: its keys win over the call's
      sowing_robot::scenario_file::applyProfileTo(
          sowing_robot::scenario_file::resolveProfile(profile_name, SOWING_SOURCE_DIR).file, cfg);
    } catch (const std::invalid_argument& ex) {
      throw py::value_error(ex.what());
    }
  }
  if (!patches.is_none()) {  // after the profile: a coefficient left out takes the traction in force
    if (!cfg.traction) throw py::value_error("patches need traction (True, a dict, or a profile that turns it on)");
    std::size_t i = 0;
    for (const auto& item : patches) cfg.patches.push_back(patchOf(item, *cfg.traction, i++));
  }
  e = cfg.validate();
  if (!e.empty()) throw py::value_error(e);

  LineReference reference = lineOf(line);
  // The line is the row the seed record is sown on, from the target's start to where it is at the end.
  LineReference probe = reference;
  const Pose2D from = probe.next(0.0).pose, to = probe.next(sc.duration).pose;
  SeedRecorder seeds(
      SeedDrill(cfg.seeding, {RowSegment{Eigen::Vector2d(from.x, from.y), Eigen::Vector2d(to.x, to.y)}}, {}, 0.0),
      cfg.tool);
  EstimatedTrace columns;
  LoopResult r;
  {
    py::gil_scoped_release no_gil;  // pure C++ from here; the trace is collected in C++ vectors
    try {
      if (trace) columns.reserve(static_cast<std::size_t>(sc.steps() + 1));
      r = runClosedLoop(sc, cfg, reference, keep_samples, [&columns, &seeds, trace](const EstimatedSample& s) {
        seeds.add(s);
        if (trace) columns.add(s);
      });
    } catch (const std::invalid_argument& ex) {
      py::gil_scoped_acquire gil;
      throw py::value_error(ex.what());
    }
  }
  py::dict d = resultDict(sc, r.run);
  d["feedback"] = feedbackName(cfg.feedback);
  d["traction"] = cfg.traction.has_value();
  d["max_abs_slip"] = r.max_abs_slip;
  d["tool_down_time"] = r.tool_down_time;
  d["fed_error_rms"] = r.fed_error_rms;
  d["fed_error_max"] = r.fed_error_max;
  d["fed_heading_error_max"] = r.fed_heading_error_max;
  d["odometry_error_final"] = r.odometry_error_final;
  d["odometry_error_max"] = r.odometry_error_max;
  d["fixes"] = fixCounts(r.fixes, r.fixes_lost_from_queue);
  d["profile"] = profile_name;
  d["motor"] = cfg.motor.enabled;
  d["limits"] = cfg.limits.enabled;
  d["traction_control"] = cfg.traction_control.enabled;
  d["speed_governor"] = cfg.speed_governor.enabled;
  d["hitch_control"] = cfg.hitch_control.enabled;
  d["hitch_raises"] = r.hitch_raises;
  d["unsown_distance"] = r.unsown_distance;
  d["mean_sowing_depth"] = r.meanSowingDepth();
  d["traction_control_time"] = r.traction_control_time;
  d["governor_min_rate"] = r.governor_min_rate;
  if (trace) d["trace"] = columns.toDict();
  d["seeds"] = seedsDict(seeds.seeds());
  d["seed_figures"] = seedFiguresDict(seedFigures(seeds.seeds(), seeds.drill(), &seeds.passes()));
  return d;
}

}  // namespace

void bindEstimated(py::module& m) {
  withPlantKeywords([&m](auto&&... plant) {
    m.def("run_estimated", &runEstimatedPy, py::kw_only(), py::arg("controller") = std::string("kanayama+atsmc"),
          py::arg("params") = py::none(), py::arg("gains") = py::none(), py::arg("feedback") = std::string("fused"),
          py::arg("traction") = py::none(), py::arg("patches") = py::none(), py::arg("sensors") = py::none(),
          py::arg("estimator") = py::none(), py::arg("motor") = py::none(), py::arg("limits") = py::none(),
          py::arg("traction_control") = py::none(), py::arg("speed_governor") = py::none(),
          py::arg("hitch_control") = py::none(), py::arg("profile") = py::none(), plant...,
          py::arg("keep_samples") = true, py::arg("trace") = false,
          R"doc(core::runClosedLoop: run() with an estimate in the loop, scored on the truth (as run_monitor).

feedback: what the controllers are fed: "ground_truth" (then equal to run(), bit for bit), "odometry" (the
wheel encoders' dead reckoning) or "fused" (the EKF of state_estimator: encoders, yaw rate, late fix).
traction: None = the no-slip plant; True = the traction plant with config/traction.yaml's defaults; a dict of
plant_sim's traction/ keys ({"mu_peak": 0.35, "draft_force": 10.0}). patches: soil patches (traction only):
[{"polygon": [[x, y], ...], "mu_peak": 0.2, "mu_slide": 0.15, "rolling_resistance": 0.08}], a coefficient
left out taking the traction block's. sensors: plant_sim's sensors/ keys ({"seed": 3, "fix": {"sigma":
0.05}}); estimator: state_estimator's estimator/ keys ({"fix": {"gate": 0}}). The drive train (docs/drive_train.md):
motor: plant_sim's motor/ keys ({"enabled": True}), limits: kinematic_controller's limits/ keys (the outer loop's
command bounded), traction_control: torque_controller's traction_control/ keys,
speed_governor: reference_generator's speed_governor/ keys, hitch_control: torque_controller's hitch_control/ keys. profile: a profile's name ("field":
config/profiles/field.yaml, what sim.launch profile:=field and benchmark --profile apply) or a file path, read as
the benchmark reads it (scenario_file::resolveProfile) and applied on top of the blocks above (its keys win; its
feedback replaces feedback=; its blocks only: the gains tuned for it, config/tuned/field/PAIR.yaml, go in params=);
patches then take the traction in force. Other arguments as run()'s.
Returns run()'s dict plus "feedback", "traction", "max_abs_slip", "tool_down_time", "fed_error_rms",
"fed_error_max", "fed_heading_error_max" (the fed pose against the truth), "odometry_error_final",
"odometry_error_max", "fixes" ({"applied", "reanchored", "slip_onsets", "gated", "too_old", "future",
"invalid", "lost_from_queue"}), "profile" (its name, "" for none), "motor", "limits", "traction_control", "speed_governor", "hitch_control" (on
or off), "traction_control_time" (s a wheel slipped beyond the target), "governor_min_rate", "hitch_raises",
"unsown_distance" (m of row the raised tool missed), "mean_sowing_depth" (m); with trace=True run()'s columns plus fed_x, fed_y, fed_theta, fed_v, fed_omega,
slip_right, slip_left, tool_down, tool_depth (m, 0 with the tool up). Raises ValueError for a bad name, key or value (naming the key).)doc");
  });
}

}  // namespace py_core
