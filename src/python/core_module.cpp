// sowing_robot.core: the ROS-free core seen from Python (pybind11). One definition of the metrics and
// the closed loop: analyze_bag, the tests and notebooks call this code instead of copies of it.
//   MetricsAccumulator, metrics(), time_domain_metrics(), metrics_table()  (core/metrics.h)
//   run_closed_loop(), run()      (core/runner.h on the line; run: any controller pair and parameters)
//   tune(), tunable_gains(), gains_yaml()                                  (core/tuning.h: the PSO tuner)
// Arrays in are 1-D float64 NumPy arrays (anything convertible); metrics out are plain dicts
// {"x": {"ise": .., ..., "peak": ..}, "y": {...}, "theta": {...}}, so they compare with == to the bit.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sowing_robot/core/metrics.h"
#include "sowing_robot/core/reference.h"
#include "sowing_robot/core/runner.h"
#include "sowing_robot/core/tuning.h"

namespace py = pybind11;
using namespace sowing_robot::core;

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Metrics = std::array<AxisMetrics, AXIS_COUNT>;

const char* const kAxes[AXIS_COUNT] = {"x", "y", "theta"};

struct Field {
  const char* name;
  double AxisMetrics::*member;
};
// Table order (metricsTable's rows), then the peak.
const Field kFields[] = {{"ise", &AxisMetrics::ise},
                         {"itse", &AxisMetrics::itse},
                         {"iae", &AxisMetrics::iae},
                         {"itae", &AxisMetrics::itae},
                         {"rise_time", &AxisMetrics::rise_time},
                         {"settling_time", &AxisMetrics::settling_time},
                         {"overshoot", &AxisMetrics::overshoot},
                         {"peak", &AxisMetrics::peak}};

py::dict axisToDict(const AxisMetrics& m) {
  py::dict d;
  for (const auto& f : kFields) d[f.name] = m.*f.member;
  return d;
}

py::dict metricsToDict(const Metrics& m) {
  py::dict d;
  for (int a = 0; a < AXIS_COUNT; ++a) d[kAxes[a]] = axisToDict(m[a]);
  return d;
}

/// The inverse, for metrics_table: every field but the peak is required (the table does not show it).
Metrics metricsFromDict(const py::dict& d) {
  Metrics m{};
  for (int a = 0; a < AXIS_COUNT; ++a) {
    if (!d.contains(kAxes[a])) throw py::key_error(std::string("metrics without axis '") + kAxes[a] + "'");
    const py::dict axis = d[kAxes[a]].cast<py::dict>();
    for (const auto& f : kFields) {
      if (axis.contains(f.name))
        m[a].*f.member = axis[f.name].cast<double>();
      else if (std::string(f.name) != "peak")
        throw py::key_error(std::string("metrics of axis '") + kAxes[a] + "' without '" + f.name + "'");
    }
  }
  return m;
}

py::array_t<double> toArray(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

void checkSameLength(const Array& t, const Array& ex, const Array& ey, const Array& eth) {
  if (t.ndim() != 1 || ex.ndim() != 1 || ey.ndim() != 1 || eth.ndim() != 1)
    throw py::value_error("t, ex, ey, etheta must be 1-D arrays");
  if (ex.size() != t.size() || ey.size() != t.size() || eth.size() != t.size())
    throw py::value_error("t, ex, ey, etheta must have the same length");
}

/// MetricsAccumulator::add over arrays, in order; returns the number accepted.
std::size_t addSamples(MetricsAccumulator& acc, const Array& t, const Array& ex, const Array& ey, const Array& eth) {
  checkSameLength(t, ex, ey, eth);
  const double *pt = t.data(), *px = ex.data(), *py_ = ey.data(), *pth = eth.data();
  const auto n = static_cast<std::size_t>(t.size());
  acc.reserve(acc.samples() + n);
  std::size_t accepted = 0;
  for (std::size_t i = 0; i < n; ++i) accepted += acc.add(pt[i], px[i], py_[i], pth[i]) ? 1 : 0;
  return accepted;
}

/// Time series of one closed-loop run, one vector per column.
struct Trace {
  std::vector<std::string> names = {
      "t",       "x",         "y",      "theta",   "v",         "omega",    "x_ref", "y_ref",   "theta_ref",
      "v_ref",   "omega_ref", "v_d",    "omega_d", "tau_right", "tau_left", "e_v",   "e_omega", "s_v",
      "s_omega", "saturated", "m0_hat", "i0_hat",  "ex",        "ey",       "etheta"};
  std::vector<std::vector<double>> columns = std::vector<std::vector<double>>(names.size());

  void reserve(std::size_t n) {
    for (auto& c : columns) c.reserve(n);
  }
  void add(const LoopSample& s) {
    const State& x = *s.state;
    const double row[] = {s.t,
                          x[X],
                          x[Y],
                          x[THETA],
                          x[V],
                          x[OMEGA],
                          s.reference->pose.x,
                          s.reference->pose.y,
                          s.reference->pose.theta,
                          s.reference->v,
                          s.reference->omega,
                          s.desired->v,
                          s.desired->omega,
                          s.control->torques.right,
                          s.control->torques.left,
                          s.control->e_v,
                          s.control->e_omega,
                          s.control->s_v,
                          s.control->s_omega,
                          s.control->saturated ? 1.0 : 0.0,
                          s.m0_hat,
                          s.i0_hat,
                          s.ex,
                          s.ey,
                          s.etheta};
    for (std::size_t i = 0; i < columns.size(); ++i) columns[i].push_back(row[i]);
  }
  py::dict toDict() const {
    py::dict d;
    for (std::size_t i = 0; i < names.size(); ++i) d[names[i].c_str()] = toArray(columns[i]);
    return d;
  }
};

/// The plant / timing part of a scenario, shared by run_closed_loop, run and tune.
struct PlantArgs {
  double duration;
  std::int64_t control_period_ns;
  bool disturbance;
  double mass_scale, inertia_scale, noise_std;
  std::uint64_t seed;
  std::array<double, 3> start;
  double disturbance_phase;
};

void applyPlant(Scenario& sc, const PlantArgs& a) {
  sc.duration = a.duration;
  sc.control_period_ns = a.control_period_ns;
  sc.disturbance.sinusoidal = a.disturbance;
  sc.disturbance.mass_scale = a.mass_scale;
  sc.disturbance.inertia_scale = a.inertia_scale;
  sc.disturbance.noise_std = a.noise_std;
  sc.disturbance.seed = a.seed;
  sc.start = {a.start[0], a.start[1], a.start[2]};
  sc.disturbance_phase = a.disturbance_phase;
}

/// A Python value as a table value (bool before int: Python's bool is an int).
ParamValue toParamValue(const py::handle& v, const std::string& where) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>();
  if (py::isinstance<py::int_>(v)) return static_cast<int>(v.cast<long long>());
  if (py::isinstance<py::float_>(v)) return v.cast<double>();
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  throw py::type_error(where + ": a bool, int, float or str is needed, got " + std::string(py::str(v.get_type())));
}

/// params: {node: {key: value}} as in a gains YAML (yaml.safe_load of config/tuned/*.yaml), or
/// {"node/key": value}.
void applyParams(Scenario& sc, const std::string& node, const std::string& key, const py::handle& v) {
  if (py::isinstance<py::dict>(v)) {
    for (const auto& kv : v.cast<py::dict>()) {
      const std::string k = kv.first.cast<std::string>();
      if (node.empty())
        applyParams(sc, k, "", kv.second);
      else
        applyParams(sc, node, key.empty() ? k : key + "/" + k, kv.second);
    }
    return;
  }
  std::string n = node, k = key;
  if (k.empty()) {  // "node/key": value
    const auto slash = n.find('/');
    if (slash == std::string::npos) throw py::value_error("params: '" + n + "' is no node/key");
    k = n.substr(slash + 1);
    n = n.substr(0, slash);
  }
  const std::string e = setControllerParam(sc, n, k, toParamValue(v, n + "/" + k));
  if (!e.empty()) throw py::value_error(e);
}

/// The scenario of `controller` ("outer+inner") with params (gains YAML shape) and gains ({name: value},
/// tunable gains of the pair) applied over the core defaults, then the plant arguments.
Scenario buildScenario(const std::string& controller, const py::object& params, const py::object& gains,
                       const PlantArgs& plant) {
  Scenario sc;
  std::string e = parseControllerPair(controller, sc.outer, sc.inner, sc.sliding.adaptive);
  if (!e.empty()) throw py::value_error(e);
  if (!params.is_none()) {
    if (!py::isinstance<py::dict>(params)) throw py::type_error("params must be a dict {node: {key: value}}");
    applyParams(sc, "", "", params);
  }
  if (!gains.is_none()) {
    for (const auto& kv : gains.cast<py::dict>()) {
      const std::string name = kv.first.cast<std::string>();
      if (!setGain(sc, name, kv.second.cast<double>()))
        throw py::value_error("'" + name + "' is no tunable gain of " + sc.controllerName());
    }
  }
  applyPlant(sc, plant);
  e = sc.validate();
  if (!e.empty()) throw py::value_error(e);
  return sc;
}

LineReference lineOf(const std::optional<std::array<double, 3>>& line) {
  return line ? LineReference((*line)[0], (*line)[1], (*line)[2]) : LineReference();
}

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
  py::dict d;
  d["controller"] = sc.controllerName();
  d["metrics"] = metricsToDict(r.metrics);
  std::vector<double> final_state(r.final_state.data(), r.final_state.data() + r.final_state.size());
  d["final_state"] = toArray(final_state);
  d["diverged"] = r.diverged;
  d["periods"] = r.periods;
  d["saturated_steps"] = r.saturated_steps;
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

Metrics (include/sowing_robot/core/metrics.h): trapezoidal ISE/ITSE/IAE/ITAE and the time-domain
figures (rise/settling time, overshoot, peak) of the world-frame tracking errors. Results are dicts
{"x": {...}, "y": {...}, "theta": {...}} with the keys of FIELDS, computed by the same code as
run_monitor, run_scenario and the PSO tuner, so they are equal (==) to theirs.

Closed loop (include/sowing_robot/core/runner.h): run_closed_loop() steps plant, Kanayama and the
sliding-mode controller on the thesis's line, as the lockstep node pipeline does.)doc";
  m.attr("AXES") = py::make_tuple("x", "y", "theta");
  py::list fields;
  for (const auto& f : kFields) fields.append(f.name);
  m.attr("FIELDS") = py::tuple(fields);

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

  m.def("run", &runPy, py::kw_only(), py::arg("controller") = std::string("kanayama+atsmc"),
        py::arg("params") = py::none(), py::arg("gains") = py::none(), py::arg("duration") = defaults.duration,
        py::arg("control_period_ns") = defaults.control_period_ns,
        py::arg("disturbance") = defaults.disturbance.sinusoidal,
        py::arg("mass_scale") = defaults.disturbance.mass_scale,
        py::arg("inertia_scale") = defaults.disturbance.inertia_scale,
        py::arg("noise_std") = defaults.disturbance.noise_std, py::arg("seed") = defaults.disturbance.seed,
        py::arg("start") = std::array<double, 3>{defaults.start.x, defaults.start.y, defaults.start.theta},
        py::arg("disturbance_phase") = defaults.disturbance_phase, py::arg("line") = py::none(),
        py::arg("keep_samples") = true, py::arg("trace") = false,
        R"doc(core::runClosedLoop of any controller pair on the line (None: the thesis's row).

controller: "outer+inner", outer kanayama|pure_pursuit|rpp, inner atsmc|tsmc|pid.
params: controller parameters by node, in the nodes' keys, as in a gains YAML: {"kinematic_controller":
{"kx": 2.0, "lookahead_dist": 0.5}, "torque_controller": {"adaptation": "eq_4_22", "kp": 3}}
(yaml.safe_load of config/tuned/<pair>.yaml as it is), or flat {"torque_controller/k1": 400.0}.
gains: {name: value} of the pair's tunable gains (tunable_gains()). Plant arguments as run_closed_loop's.
Returns run_closed_loop's dict plus "controller". Raises ValueError for a bad name, key or value.)doc");

  m.def("tune", &tunePy, py::kw_only(), py::arg("controller") = std::string("kanayama+atsmc"),
        py::arg("params") = py::none(), py::arg("gains") = py::none(), py::arg("bounds") = py::none(),
        py::arg("particles") = 20, py::arg("iterations") = 30, py::arg("pso_seed") = 1, py::arg("threads") = 0,
        py::arg("velocity_clamp") = 0.2, py::arg("w_max") = 0.9, py::arg("w_min") = 0.1, py::arg("c1") = 2.0,
        py::arg("c2") = 2.0, py::arg("cost") = std::string("itae"), py::arg("torque_weight") = 0.0,
        py::arg("chattering_weight") = 0.0, py::arg("duration") = defaults.duration,
        py::arg("control_period_ns") = defaults.control_period_ns,
        py::arg("disturbance") = defaults.disturbance.sinusoidal,
        py::arg("mass_scale") = defaults.disturbance.mass_scale,
        py::arg("inertia_scale") = defaults.disturbance.inertia_scale,
        py::arg("noise_std") = defaults.disturbance.noise_std, py::arg("seed") = defaults.disturbance.seed,
        py::arg("start") = std::array<double, 3>{defaults.start.x, defaults.start.y, defaults.start.theta},
        py::arg("disturbance_phase") = defaults.disturbance_phase, py::arg("line") = py::none(),
        R"doc(core::tuneGains: the pso_tuner node's PSO on the scenario run() would build.

bounds: [(name, lower, upper), ...]; None = every tunable gain of the pair in its default bounds
(tunable_gains()). PSO settings as config/pso.yaml's (velocity_clamp 0.2). Same arguments, same
result, bit for bit, whatever `threads`. Returns {"best_gains": {name: value}, "best_cost",
"initial_best_cost", "cost_per_iteration" (array), "tracking", "effort", "chattering", "evaluations",
"evaluations_cut", "threads", "wall_s", "bounds", "yaml" (the gains YAML body of the tuned pair)}.)doc");

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
}
