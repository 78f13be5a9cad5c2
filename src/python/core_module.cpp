// sowing_robot.core: the ROS-free core seen from Python (pybind11). One definition of the metrics and
// the closed loop: analyze_bag, the tests and notebooks call this code instead of copies of it.
//   MetricsAccumulator, metrics(), time_domain_metrics(), metrics_table()  (core/metrics.h)
//   run_closed_loop()                                                      (core/runner.h, line reference)
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

py::dict runClosedLoopPy(bool adaptive, double duration, std::int64_t control_period_ns, bool disturbance,
                         double mass_scale, double inertia_scale, double noise_std, std::uint64_t seed,
                         const std::array<double, 3>& start, const std::string& switching, double width,
                         const std::optional<std::array<double, 3>>& line, bool keep_samples, bool trace) {
  Scenario sc;
  sc.sliding.adaptive = adaptive;
  sc.duration = duration;
  sc.control_period_ns = control_period_ns;
  sc.disturbance.sinusoidal = disturbance;
  sc.disturbance.mass_scale = mass_scale;
  sc.disturbance.inertia_scale = inertia_scale;
  sc.disturbance.noise_std = noise_std;
  sc.disturbance.seed = seed;
  sc.start = {start[0], start[1], start[2]};
  if (!SwitchFunction::parse(switching, sc.sliding.switching.type))
    throw py::value_error("unknown switching function '" + switching + "' (sign, sat, relay, atan, tanh)");
  sc.sliding.switching.width = width;
  const std::string err = sc.validate();
  if (!err.empty()) throw py::value_error(err);
  LineReference reference = line ? LineReference((*line)[0], (*line)[1], (*line)[2]) : LineReference();
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
  d["metrics"] = metricsToDict(r.metrics);
  std::vector<double> final_state(r.final_state.data(), r.final_state.data() + r.final_state.size());
  d["final_state"] = toArray(final_state);
  d["diverged"] = r.diverged;
  d["periods"] = r.periods;
  d["saturated_steps"] = r.saturated_steps;
  if (trace) d["trace"] = columns.toDict();
  return d;
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
}
