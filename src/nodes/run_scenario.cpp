// run_scenario: the thesis closed loop in-process (no ROS), for quick comparisons and benchmarks.
//   run_scenario [--tsmc] [--atsmc] [--disturbance] [--mismatch S] [--noise STD] [--duration T] [--rate HZ]
//                [--switching NAME --width W] [--repeat N] [--yaml FILE (metrics of the last mode)]
// Prints the Table 5.5/5.6 metrics as Markdown and the wall time per run.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "sowing_robot/core/runner.h"

using namespace sowing_robot::core;

int main(int argc, char** argv) {
  std::vector<bool> modes;
  Scenario sc;
  int repeat = 1;
  std::string yaml;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* what) {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "run_scenario: %s needs a value\n", what);
        std::exit(2);
      }
      return std::strtod(argv[++i], nullptr);
    };
    if (a == "--tsmc") modes.push_back(false);
    else if (a == "--atsmc") modes.push_back(true);
    else if (a == "--disturbance") sc.disturbance.sinusoidal = true;
    else if (a == "--mismatch") sc.disturbance.mass_scale = sc.disturbance.inertia_scale = value("--mismatch");
    else if (a == "--noise") sc.disturbance.noise_std = value("--noise");
    else if (a == "--duration") sc.duration = value("--duration");
    else if (a == "--rate") sc.control_period_ns = static_cast<std::int64_t>(1e9 / value("--rate") + 0.5);
    else if (a == "--width") sc.sliding.switching.width = value("--width");
    else if (a == "--repeat") repeat = static_cast<int>(value("--repeat"));
    else if (a == "--yaml" && i + 1 < argc) yaml = argv[++i];
    else if (a == "--switching" && i + 1 < argc) {
      if (!SwitchFunction::parse(argv[++i], sc.sliding.switching.type)) {
        std::fprintf(stderr, "run_scenario: unknown switching '%s'\n", argv[i]);
        return 2;
      }
    } else {
      std::fprintf(stderr, "run_scenario: unknown argument '%s'\n", a.c_str());
      return 2;
    }
  }
  if (modes.empty()) modes = {true, false};
  std::vector<std::string> names;
  std::vector<std::array<AxisMetrics, AXIS_COUNT>> results;
  for (bool adaptive : modes) {
    sc.sliding.adaptive = adaptive;
    const std::string err = sc.validate();
    if (!err.empty()) {
      std::fprintf(stderr, "run_scenario: %s\n", err.c_str());
      return 2;
    }
    LineReference ref;
    RunResult r;
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < repeat; ++k) r = runClosedLoop(sc, ref);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / repeat;
    std::printf("%s: %.3f ms wall per %.1f s run (%.2f M steps/s), final (x %.4f, y %.4f, theta %.5f), "
                "%ld saturated periods%s\n",
                adaptive ? "ATSMC" : "TSMC", 1e3 * s, sc.duration, (sc.steps() + 1) / s / 1e6, r.final_state[X],
                r.final_state[Y], r.final_state[THETA], static_cast<long>(r.saturated_steps),
                r.diverged ? ", DIVERGED" : "");
    names.push_back(adaptive ? "atsmc" : "tsmc");
    results.push_back(r.metrics);
    if (!yaml.empty() && !writeMetricsYaml(yaml, names.back(), r.metrics)) {
      std::fprintf(stderr, "run_scenario: cannot write %s\n", yaml.c_str());
      return 2;
    }
  }
  std::printf("\n%s", metricsTable(names, results).c_str());
  return 0;
}
