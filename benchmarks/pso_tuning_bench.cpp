// pso_tuning_bench: wall time of the full offline PSO tuning of the thesis scenario (the pso_tuner
// node's objective, without ROS) for several thread counts.
//   pso_tuning_bench [--threads 1,2] [--particles 20] [--iterations 30] [--duration 25] [--rate 1000]
//                    [--seed 1] [--mode atsmc|tsmc]
// Scenario: 25 s at 1 kHz, start (-1, 0, 0), line x = t, y = 3, sinusoidal wheel disturbance
// (A 2.75 N·m, w 3 rad/s), plant 20 % heavier than the model; Table 5.1 robot; ITAE cost; default
// search space (core::defaultGainBounds) and config/pso.yaml's PSO settings (velocity clamp 0.2).
// Prints wall time, speed-up over the first thread count, evaluations and simulation throughput, and
// checks that every thread count found the same optimum (psoMinimize is deterministic).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "sowing_robot/core/evaluation/tuning.h"

using namespace sowing_robot::core;

int main(int argc, char** argv) {
  std::vector<int> thread_counts{1, 2};
  Scenario sc;
  sc.disturbance.sinusoidal = true;
  sc.disturbance.mass_scale = sc.disturbance.inertia_scale = 1.2;
  PsoParams pso;
  pso.max_velocity_fraction = 0.2;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) {
      std::fprintf(stderr, "pso_tuning_bench: unknown argument or missing value: '%s'\n", a.c_str());
      return 2;
    }
    const char* v = argv[++i];
    if (a == "--threads") {
      thread_counts.clear();
      std::string list = v;
      for (std::size_t pos = 0; pos <= list.size();) {
        const std::size_t comma = std::min(list.find(',', pos), list.size());
        thread_counts.push_back(std::atoi(list.substr(pos, comma - pos).c_str()));
        pos = comma + 1;
      }
    } else if (a == "--particles")
      pso.particles = std::atoi(v);
    else if (a == "--iterations")
      pso.iterations = std::atoi(v);
    else if (a == "--duration")
      sc.duration = std::strtod(v, nullptr);
    else if (a == "--rate")
      sc.control_period_ns = static_cast<std::int64_t>(1e9 / std::strtod(v, nullptr) + 0.5);
    else if (a == "--seed")
      pso.seed = std::strtoull(v, nullptr, 10);
    else if (a == "--mode")
      sc.sliding.adaptive = std::strcmp(v, "tsmc") != 0;
    else {
      std::fprintf(stderr, "pso_tuning_bench: unknown argument '%s'\n", a.c_str());
      return 2;
    }
  }

  const LineReference reference(1.0, 3.0, 0.0);
  const std::vector<GainBounds> bounds = defaultGainBounds();
  const TuningObjective objective;
  std::printf(
      "PSO tuning bench: %d particles x (%d + 1) iterations, %s, %.4g s at %.0f Hz per evaluation, "
      "%u hardware threads\n",
      pso.particles, pso.iterations, sc.sliding.adaptive ? "ATSMC" : "TSMC", sc.duration,
      1e9 / static_cast<double>(sc.control_period_ns), std::thread::hardware_concurrency());
  // Evaluations whose run stopped once it could not beat its particle's personal best ("cut short") are
  // the tuner's bound (tuning.h): the same search as with whole runs, fewer simulated seconds.
  std::printf(
      "\n| threads | wall [s] | speed-up | evaluations | cut short | ms / evaluation | simulated s | "
      "sim s / wall s | sim s / wall s / thread | initial best | best cost |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  double first_wall = 0.0, first_best = 0.0;
  bool same = true;
  for (std::size_t k = 0; k < thread_counts.size(); ++k) {
    pso.threads = thread_counts[k];
    TuningResult r;
    try {
      r = tuneGains(sc, reference, bounds, objective, pso);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "pso_tuning_bench: %s\n", e.what());
      return 2;
    }
    if (k == 0) {
      first_wall = r.wall_s;
      first_best = r.pso.best_cost;
    } else if (r.pso.best_cost != first_best) {
      same = false;
    }
    const double sim = r.simulated_s;
    std::printf("| %d | %.3f | %.2f | %ld | %ld | %.3f | %.0f | %.0f | %.0f | %.6g | %.6g |\n", r.threads, r.wall_s,
                first_wall / r.wall_s, r.pso.evaluations, r.evaluations_cut,
                1e3 * r.wall_s / static_cast<double>(r.pso.evaluations), sim, sim / r.wall_s,
                sim / r.wall_s / r.threads, r.initial_best_cost, r.pso.best_cost);
    std::fflush(stdout);
    if (k + 1 == thread_counts.size()) {
      std::printf("\nbest gains:");
      for (std::size_t d = 0; d < bounds.size(); ++d) std::printf(" %s %.5g", bounds[d].name.c_str(), r.best_gains[d]);
      std::printf("\n");
    }
  }
  std::printf("same optimum for every thread count: %s\n", same ? "yes" : "NO");
  return same ? 0 : 1;
}
