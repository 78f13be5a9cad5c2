// The conversions the sowing_robot.core bindings share (core_module.cpp, estimated_binding.cpp): metrics
// and arrays to Python, a Scenario from the run()/tune() keyword arguments, the per-period trace.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/evaluation/tuning.h"
#include "sowing_robot/core/simulation/metrics.h"
#include "sowing_robot/core/simulation/runner.h"

namespace py_core {

namespace py = pybind11;
using namespace sowing_robot::core;

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Metrics = std::array<AxisMetrics, AXIS_COUNT>;

/// A metrics dict's fields: the figures of the table and the YAML (axisFigures(), simulation/metrics.h), then
/// the peak.
struct Field {
  const char* name;
  double AxisMetrics::*member;
};
inline const std::vector<Field>& dictFields() {
  static const std::vector<Field> fields = [] {
    std::vector<Field> f;
    for (const AxisFigure& a : axisFigures()) f.push_back({a.name, a.member});
    f.push_back({"peak", &AxisMetrics::peak});
    return f;
  }();
  return fields;
}

inline py::dict axisToDict(const AxisMetrics& m) {
  py::dict d;
  for (const auto& f : dictFields()) d[f.name] = m.*f.member;
  return d;
}

inline py::dict metricsToDict(const Metrics& m) {
  py::dict d;
  for (int a = 0; a < AXIS_COUNT; ++a) d[axisName(a)] = axisToDict(m[a]);
  return d;
}

/// The inverse, for metrics_table: every field but the peak is required (the table does not show it).
inline Metrics metricsFromDict(const py::dict& d) {
  Metrics m{};
  for (int a = 0; a < AXIS_COUNT; ++a) {
    if (!d.contains(axisName(a))) throw py::key_error(std::string("metrics without axis '") + axisName(a) + "'");
    const py::dict axis = d[axisName(a)].cast<py::dict>();
    for (const auto& f : dictFields()) {
      if (axis.contains(f.name))
        m[a].*f.member = axis[f.name].cast<double>();
      else if (std::string(f.name) != "peak")
        throw py::key_error(std::string("metrics of axis '") + axisName(a) + "' without '" + f.name + "'");
    }
  }
  return m;
}

inline py::array_t<double> toArray(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

inline void checkSameLength(const Array& t, const Array& ex, const Array& ey, const Array& eth) {
  if (t.ndim() != 1 || ex.ndim() != 1 || ey.ndim() != 1 || eth.ndim() != 1)
    throw py::value_error("t, ex, ey, etheta must be 1-D arrays");
  if (ex.size() != t.size() || ey.size() != t.size() || eth.size() != t.size())
    throw py::value_error("t, ex, ey, etheta must have the same length");
}

/// MetricsAccumulator::add over arrays, in order; returns the number accepted.
inline std::size_t addSamples(MetricsAccumulator& acc, const Array& t, const Array& ex, const Array& ey,
                              const Array& eth) {
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

inline void applyPlant(Scenario& sc, const PlantArgs& a) {
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
inline ParamValue toParamValue(const py::handle& v, const std::string& where) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>();
  if (py::isinstance<py::int_>(v)) return static_cast<int>(v.cast<long long>());
  if (py::isinstance<py::float_>(v)) return v.cast<double>();
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  throw py::type_error(where + ": a bool, int, float or str is needed, got " + std::string(py::str(v.get_type())));
}

/// params: {node: {key: value}} as in a gains YAML (yaml.safe_load of config/tuned/*.yaml), or
/// {"node/key": value}.
inline void applyParams(Scenario& sc, const std::string& node, const std::string& key, const py::handle& v) {
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
inline Scenario buildScenario(const std::string& controller, const py::object& params, const py::object& gains,
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

inline LineReference lineOf(const std::optional<std::array<double, 3>>& line) {
  return line ? LineReference((*line)[0], (*line)[1], (*line)[2]) : LineReference();
}

/// The part of a run's dict every runner returns: controller, metrics, final_state, diverged, periods,
/// saturated_steps.
inline py::dict resultDict(const Scenario& sc, const RunResult& r) {
  py::dict d;
  d["controller"] = sc.controllerName();
  d["metrics"] = metricsToDict(r.metrics);
  std::vector<double> final_state(r.final_state.data(), r.final_state.data() + r.final_state.size());
  d["final_state"] = toArray(final_state);
  d["diverged"] = r.diverged;
  d["periods"] = r.periods;
  d["saturated_steps"] = r.saturated_steps;
  return d;
}

/// The plant and timing keywords of run(), tune() and run_estimated() (what PlantArgs and lineOf take), with
/// the core's defaults: expanded into each m.def with withPlantKeywords().
inline auto plantKeywords() {
  const Scenario d;
  return std::make_tuple(py::arg("duration") = d.duration, py::arg("control_period_ns") = d.control_period_ns,
                         py::arg("disturbance") = d.disturbance.sinusoidal,
                         py::arg("mass_scale") = d.disturbance.mass_scale,
                         py::arg("inertia_scale") = d.disturbance.inertia_scale,
                         py::arg("noise_std") = d.disturbance.noise_std, py::arg("seed") = d.disturbance.seed,
                         py::arg("start") = std::array<double, 3>{d.start.x, d.start.y, d.start.theta},
                         py::arg("disturbance_phase") = d.disturbance_phase, py::arg("line") = py::none());
}
/// def(plant keywords...): the caller's m.def with the plant keywords in place.
template <typename Def>
void withPlantKeywords(Def def) {
  std::apply([&def](auto&&... keywords) { def(std::forward<decltype(keywords)>(keywords)...); }, plantKeywords());
}

/// Registers run_estimated (estimated_binding.cpp).
void bindEstimated(py::module& m);

}  // namespace py_core
