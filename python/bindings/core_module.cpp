// sowing_robot.core: the ROS-free core seen from Python (pybind11). One definition of the metrics and
// the closed loop: analyze_bag, the tests and notebooks call this code instead of copies of it.
//   MetricsAccumulator, metrics(), time_domain_metrics(), metrics_table()  (core/simulation/metrics.h)
//   run_closed_loop(), run()      (core/simulation/runner.h on the line; run: any controller pair and parameters)
//   tune(), tunable_gains(), gains_yaml()                                  (core/evaluation/tuning.h: the PSO tuner)
// Arrays in are 1-D float64 NumPy arrays (anything convertible); metrics out are plain dicts
// {"x": {"ise": .., ..., "peak": ..}, "y": {...}, "theta": {...}}, so they compare with == to the bit.
#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core_bindings.h"
#include "sowing_robot/core/evaluation/run_metrics.h"

namespace py = pybind11;
using namespace sowing_robot::core;

namespace {

using namespace py_core;

py::dict runScenario(const Scenario& sc, LineReference reference, bool keep_samples, bool trace) {
  Trace columns;
  RunResult r;
  {
    py::gil_scoped_release no_gil;  // pure C++ from here; the trace is collected in C++ vectors
    if (trace) {
      columns.reserve(static_cast<std::size_t>(sc.steps() + 1));
      r = runClosedLoop(sc, reference, keep_samples, [&columns](const LoopSample& s) { columns.add(s); });
    } else {
      r = runClosedLoop(sc, reference, keep_samples);
    }
  }
  py::dict d = resultDict(sc, r);
  if (trace) d["trace"] = columns.toDict();
  return d;
}

py::dict runClosedLoopPy(bool adaptive, double duration, std::int64_t control_period_ns, bool disturbance,
                         double mass_scale, double inertia_scale, double noise_std, std::uint64_t seed,
                         const std::array<double, 3>& start, const std::string& switching, double width,
                         const std::optional<std::array<double, 3>>& line, bool keep_samples, bool trace) {
  Scenario sc;
  sc.sliding.adaptive = adaptive;
  applyPlant(sc, {duration, control_period_ns, disturbance, mass_scale, inertia_scale, noise_std, seed, start, 0.0});
  if (!SwitchFunction::parse(switching, sc.sliding.switching.type))
    throw py::value_error("unknown switching function '" + switching + "' (sign, sat, relay, atan, tanh)");
  sc.sliding.switching.width = width;
  const std::string err = sc.validate();
  if (!err.empty()) throw py::value_error(err);
  return runScenario(sc, lineOf(line), keep_samples, trace);
}

py::dict runPy(const std::string& controller, const py::object& params, const py::object& gains, double duration,
               std::int64_t control_period_ns, bool disturbance, double mass_scale, double inertia_scale,
               double noise_std, std::uint64_t seed, const std::array<double, 3>& start, double disturbance_phase,
               const std::optional<std::array<double, 3>>& line, bool keep_samples, bool trace) {
  const Scenario sc = buildScenario(
      controller, params, gains,
      {duration, control_period_ns, disturbance, mass_scale, inertia_scale, noise_std, seed, start, disturbance_phase});
  return runScenario(sc, lineOf(line), keep_samples, trace);
}

std::vector<GainBounds> boundsFrom(const Scenario& sc, const py::object& bounds) {
  if (bounds.is_none()) return defaultGainBounds(sc);
  std::vector<GainBounds> out;
  for (const auto& b : bounds) {
    const auto t = b.cast<py::sequence>();
    if (t.size() != 3) throw py::value_error("bounds: one (name, lower, upper) per gain");
    out.push_back({t[0].cast<std::string>(), t[1].cast<double>(), t[2].cast<double>()});
  }
  return out;
}

py::list boundsToList(const std::vector<GainBounds>& b) {
  py::list l;
  for (const auto& g : b) l.append(py::make_tuple(g.name, g.lower, g.upper));
  return l;
}

py::dict tunePy(const std::string& controller, const py::object& params, const py::object& gains,
                const py::object& bounds, int particles, int iterations, std::uint64_t pso_seed, int threads,
                double velocity_clamp, double w_max, double w_min, double c1, double c2, const std::string& cost,
                double torque_weight, double chattering_weight, double duration, std::int64_t control_period_ns,
                bool disturbance, double mass_scale, double inertia_scale, double noise_std, std::uint64_t seed,
                const std::array<double, 3>& start, double disturbance_phase,
                const std::optional<std::array<double, 3>>& line) {
  const Scenario base = buildScenario(
      controller, params, gains,
      {duration, control_period_ns, disturbance, mass_scale, inertia_scale, noise_std, seed, start, disturbance_phase});
  const std::vector<GainBounds> box = boundsFrom(base, bounds);
  TuningObjective objective;
  if (!parseCostType(cost, objective.cost)) throw py::value_error("unknown cost '" + cost + "' (itae|ise|iae|itse)");
  objective.torque_weight = torque_weight;
  objective.chattering_weight = chattering_weight;
  PsoParams p;  // the pso_tuner node's mapping of config/pso.yaml
  p.particles = particles;
  p.iterations = iterations;
  p.seed = pso_seed;
  p.threads = threads;
  p.max_velocity_fraction = velocity_clamp;
  p.w_max = w_max;
  p.w_min = w_min;
  p.c1 = c1;
  p.c2 = c2;
  const LineReference reference = lineOf(line);
  TuningResult r;
  try {
    py::gil_scoped_release no_gil;
    r = tuneGains(base, reference, box, objective, p);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
  const Scenario tuned = TuningProblem(base, reference, box, objective, 1).scenarioFor(r.best_gains);
  py::dict best;
  for (std::size_t d = 0; d < box.size(); ++d) best[box[d].name.c_str()] = r.best_gains[d];
  py::dict out;
  out["controller"] = base.controllerName();
  out["best_gains"] = best;
  out["best_cost"] = r.pso.best_cost;
  out["initial_best_cost"] = r.initial_best_cost;
  out["cost_per_iteration"] = toArray(r.pso.best_cost_per_iteration);
  out["tracking"] = r.best.tracking;
  out["effort"] = r.best.effort;
  out["chattering"] = r.best.chattering;
  out["evaluations"] = r.pso.evaluations;
  out["evaluations_cut"] = r.evaluations_cut;
  out["threads"] = r.threads;
  out["wall_s"] = r.wall_s;
  out["bounds"] = boundsToList(box);
  out["yaml"] = gainsYaml(tuned, box);
  return out;
}

}  // namespace

PYBIND11_MODULE(core, m) {
  m.doc() = R"doc(The ROS-free sowing_robot core (C++), for Python.

Metrics (include/sowing_robot/core/simulation/metrics.h): trapezoidal ISE/ITSE/IAE/ITAE and the time-domain
figures (rise/settling time, overshoot, peak) of the world-frame tracking errors. Results are dicts
{"x": {...}, "y": {...}, "theta": {...}} with the keys of FIELDS, computed by the same code as
run_monitor, run_scenario and the PSO tuner, so they are equal (==) to theirs.

Closed loop (include/sowing_robot/core/simulation/runner.h): run_closed_loop() steps plant, Kanayama and the
sliding-mode controller on the thesis's line, as the lockstep node pipeline does.)doc";
  py::list axes, fields, table_fields;
  for (int a = 0; a < AXIS_COUNT; ++a) axes.append(axisName(a));
  m.attr("AXES") = py::tuple(axes);
  for (const auto& f : dictFields()) fields.append(f.name);
  m.attr("FIELDS") = py::tuple(fields);
  // The figures of metrics_table and of run_monitor's metrics YAML (FIELDS without the peak).
  for (const AxisFigure& f : axisFigures()) table_fields.append(f.name);
  m.attr("TABLE_FIELDS") = py::tuple(table_fields);
  m.def(
      "run_metrics", []() { return py::module_::import("json").attr("loads")(runMetricsJson()); },
      "The benchmark's per-run metrics (core/evaluation/run_metrics.h), as the benchmark writes them to "
      "metrics.json: a list of dicts with name (the runs.csv column), unit, label, meaning, format, group, "
      "aggregation, better, compared, plots, report_table, overview.");

  py::class_<MetricsAccumulator>(m, "MetricsAccumulator",
                                 "core::MetricsAccumulator: errors added sample by sample (time order).")
      .def(py::init<bool>(), py::arg("keep_samples") = true,
           "keep_samples=False computes the integrals only (rise_time, ... are then NaN).")
      .def("add", &MetricsAccumulator::add, py::arg("t"), py::arg("ex"), py::arg("ey"), py::arg("etheta"),
           "One sample; False (and counted in rejected) when any value is not finite.")
      .def("add_samples", &addSamples, py::arg("t"), py::arg("ex"), py::arg("ey"), py::arg("etheta"),
           "add() for each element of four equal-length 1-D arrays, in order; returns the number accepted.")
      .def("reserve", &MetricsAccumulator::reserve, py::arg("n"))
      .def("reset", &MetricsAccumulator::reset)
      .def(
          "result", [](const MetricsAccumulator& a) { return metricsToDict(a.result()); },
          "The metrics so far, as {axis: {field: value}}.")
      .def_property_readonly("samples", &MetricsAccumulator::samples, "Samples accepted.")
      .def_property_readonly("rejected", &MetricsAccumulator::rejected, "Samples refused (non-finite).");

  m.def(
      "metrics",
      [](const Array& t, const Array& ex, const Array& ey, const Array& eth, bool keep_samples) {
        MetricsAccumulator acc(keep_samples);
        addSamples(acc, t, ex, ey, eth);
        return metricsToDict(acc.result());
      },
      py::arg("t"), py::arg("ex"), py::arg("ey"), py::arg("etheta"), py::arg("keep_samples") = true,
      "MetricsAccumulator(keep_samples) fed with the arrays, then result().");
  m.def(
      "time_domain_metrics",
      [](const Array& t, const Array& e) {
        if (t.ndim() != 1 || e.ndim() != 1 || t.size() != e.size())
          throw py::value_error("t and e must be 1-D arrays of the same length");
        const std::vector<double> tv(t.data(), t.data() + t.size()), ev(e.data(), e.data() + e.size());
        AxisMetrics a;
        timeDomainMetrics(tv, ev, a);
        py::dict d;
        d["rise_time"] = a.rise_time;
        d["settling_time"] = a.settling_time;
        d["overshoot"] = a.overshoot;
        d["peak"] = a.peak;
        return d;
      },
      py::arg("t"), py::arg("e"), "core::timeDomainMetrics of one series: rise_time, settling_time, overshoot, peak.");
  m.def(
      "metrics_table",
      [](const std::vector<std::string>& names, const std::vector<py::dict>& runs) {
        if (names.size() != runs.size()) throw py::value_error("one name per run");
        std::vector<Metrics> m;
        for (const auto& r : runs) m.push_back(metricsFromDict(r));
        return metricsTable(names, m);
      },
      py::arg("names"), py::arg("runs"),
      "core::metricsTable: the Markdown table (%.4g) with one column per run (metrics dicts; peak optional).");

  const Scenario defaults;
  m.def("run_closed_loop", &runClosedLoopPy, py::kw_only(), py::arg("adaptive") = defaults.sliding.adaptive,
        py::arg("duration") = defaults.duration, py::arg("control_period_ns") = defaults.control_period_ns,
        py::arg("disturbance") = defaults.disturbance.sinusoidal,
        py::arg("mass_scale") = defaults.disturbance.mass_scale,
        py::arg("inertia_scale") = defaults.disturbance.inertia_scale,
        py::arg("noise_std") = defaults.disturbance.noise_std, py::arg("seed") = defaults.disturbance.seed,
        py::arg("start") = std::array<double, 3>{defaults.start.x, defaults.start.y, defaults.start.theta},
        py::arg("switching") = std::string(SwitchFunction::name(defaults.sliding.switching.type)),
        py::arg("width") = defaults.sliding.switching.width, py::arg("line") = py::none(),
        py::arg("keep_samples") = true, py::arg("trace") = false,
        R"doc(core::runClosedLoop on LineReference(v_r, row_y, x0) = line (None: the thesis's row), the thesis scenario.

adaptive: ATSMC (True) or TSMC; disturbance: the sinusoidal wheel disturbance (Fig 5.9); mass_scale,
inertia_scale: true/nominal parameters (run_scenario --mismatch sets both); noise_std, seed: torque noise.
Returns {"metrics": {axis: {field: value}}, "final_state": array (x, y, theta, v, omega, phi_r, phi_l),
"diverged": bool, "periods": int, "saturated_steps": int} and, with trace=True, "trace": {column: array}
with one row per control period (t, state, reference, command, torques, sliding variables, estimates,
errors ex, ey, etheta). Raises ValueError for an invalid scenario.)doc");

  withPlantKeywords([&m](auto&&... plant) {
    m.def("run", &runPy, py::kw_only(), py::arg("controller") = std::string("kanayama+atsmc"),
          py::arg("params") = py::none(), py::arg("gains") = py::none(), plant..., py::arg("keep_samples") = true,
          py::arg("trace") = false,
          R"doc(core::runClosedLoop of any controller pair on the line (None: the thesis's row).

controller: "outer+inner", outer kanayama|pure_pursuit|rpp, inner atsmc|tsmc|pid.
params: controller parameters by node, in the nodes' keys, as in a gains YAML: {"kinematic_controller":
{"kx": 2.0, "lookahead_dist": 0.5}, "torque_controller": {"adaptation": "eq_4_22", "kp": 3}}
(yaml.safe_load of config/tuned/<pair>.yaml as it is), or flat {"torque_controller/k1": 400.0}.
gains: {name: value} of the pair's tunable gains (tunable_gains()). Plant arguments as run_closed_loop's.
Returns run_closed_loop's dict plus "controller". Raises ValueError for a bad name, key or value.)doc");
  });

  withPlantKeywords([&m](auto&&... plant) {
    m.def("tune", &tunePy, py::kw_only(), py::arg("controller") = std::string("kanayama+atsmc"),
          py::arg("params") = py::none(), py::arg("gains") = py::none(), py::arg("bounds") = py::none(),
          py::arg("particles") = 20, py::arg("iterations") = 30, py::arg("pso_seed") = 1, py::arg("threads") = 0,
          py::arg("velocity_clamp") = 0.2, py::arg("w_max") = 0.9, py::arg("w_min") = 0.1, py::arg("c1") = 2.0,
          py::arg("c2") = 2.0, py::arg("cost") = std::string("itae"), py::arg("torque_weight") = 0.0,
          py::arg("chattering_weight") = 0.0, plant...,
          R"doc(core::tuneGains: the pso_tuner node's PSO on the scenario run() would build.

bounds: [(name, lower, upper), ...]; None = every tunable gain of the pair in its default bounds
(tunable_gains()). PSO settings as config/pso.yaml's (velocity_clamp 0.2). Same arguments, same
result, bit for bit, whatever `threads`. Returns {"best_gains": {name: value}, "best_cost",
"initial_best_cost", "cost_per_iteration" (array), "tracking", "effort", "chattering", "evaluations",
"evaluations_cut", "threads", "wall_s", "bounds", "yaml" (the gains YAML body of the tuned pair)}.)doc");
  });

  m.def(
      "tunable_gains",
      [](const std::string& controller) {
        Scenario sc;
        const std::string e = parseControllerPair(controller, sc.outer, sc.inner, sc.sliding.adaptive);
        if (!e.empty()) throw py::value_error(e);
        return boundsToList(defaultGainBounds(sc));
      },
      py::arg("controller") = std::string("kanayama+atsmc"),
      "The pair's tunable gains (the tables' `tunable` marks) with their default search bounds: [(name, lo, hi)].");

  bindEstimated(m);  // run_estimated (estimated_binding.cpp)
}
