// benchmark: Monte-Carlo statistics of controller pairs in-process (no ROS master), issue 17 item 3.
//   benchmark --controllers kanayama+atsmc,rpp+pid --seeds N --output DIR [--threads K]
//             [--scenarios thesis_line] [--base-seed S]
// Writes DIR/runs.csv (tidy, one row per run: scenario, controller, seed, the values drawn, every
// metric) and DIR/report.md (per scenario and controller: success rate with reasons, mean, std, p95,
// worst), and prints the wall time. The draws (MonteCarloSpec's defaults, core/benchmark.h): mismatch
// U(0.8, 1.5) on m0 and I0 independently, disturbance amplitude U(0, 2) N·m and phase U(0, 2 pi), wheel
// noise std 0.1 N·m with a drawn seed, start pose (-1, 0, 0) + U(+-0.5 m, +-0.5 m, +-0.3 rad); success:
// no divergence and |cross-track| < 0.05 m from 15 s to the end. Scenarios: only thesis_line so far
// (the thesis's Table 5.5 line, 25 s at 1 kHz); the scenario suite (config/scenarios/) is to come.
// An unknown name, a seed count of 0 or an unwritable DIR: one error line, exit 2, no report written.
#include <sys/stat.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "sowing_robot/core/benchmark.h"
#include "sowing_robot/core/runner.h"

using namespace sowing_robot::core;

namespace {
std::vector<std::string> splitComma(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

int fail(const std::string& message) {
  std::fprintf(stderr, "benchmark: %s\n", message.c_str());
  return 2;
}

bool parseInteger(const char* text, long long& value) {
  char* end = nullptr;
  value = std::strtoll(text, &end, 10);
  return end != text && *end == '\0';
}
}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> scenarios{"thesis_line"}, controllers{"kanayama+atsmc"};
  long long seeds = -1, threads = 0, base_seed = 1;
  std::string output;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return fail("missing value after " + a);
    const char* v = argv[++i];
    if (a == "--controllers") {
      controllers = splitComma(v);
    } else if (a == "--scenarios") {
      scenarios = splitComma(v);
    } else if (a == "--output") {
      output = v;
    } else if (a == "--seeds" || a == "--threads" || a == "--base-seed") {
      long long n;
      if (!parseInteger(v, n)) return fail(a + " needs an integer, not '" + v + "'");
      (a == "--seeds" ? seeds : a == "--threads" ? threads : base_seed) = n;
    } else {
      return fail("unknown argument '" + a + "' (--controllers --seeds --output --threads --scenarios --base-seed)");
    }
  }
  if (seeds < 1) return fail(seeds == -1 ? "--seeds N is required" : "--seeds must be >= 1");
  if (threads < 0) return fail("--threads must be >= 0 (0: all cores)");
  if (output.empty()) return fail("--output DIR is required");
  for (const auto& s : scenarios)
    if (s != "thesis_line") return fail("unknown scenario '" + s + "' (known: thesis_line)");
  std::vector<Scenario> pairs;
  for (const auto& c : controllers) {
    Scenario sc;
    const std::string e = parseControllerPair(c, sc.outer, sc.inner, sc.sliding.adaptive);
    if (!e.empty()) return fail(e);
    pairs.push_back(sc);
  }
  ::mkdir(output.c_str(), 0777);  // may exist; the writes below report a real failure
  MonteCarloSpec spec;
  spec.base_seed = static_cast<std::uint64_t>(base_seed);

  // Everything is computed first, then written: a failure leaves no partial report.
  std::string csv = runsCsvHeader(), report = "# Controller benchmark\n\n";
  report += std::to_string(seeds) + " seeded runs per scenario and controller, base seed " + std::to_string(base_seed) +
            ". Draws: mismatch U(0.8, 1.5) on m0 and I0 independently, disturbance amplitude U(0, 2) N·m and phase "
            "U(0, 2 pi), wheel noise "
            "std 0.1 N·m, start (-1, 0, 0) + U(+-0.5 m, +-0.5 m, +-0.3 rad). Success: no divergence and "
            "|cross-track| < 0.05 m from 15 s to the end.\n\n";
  const auto t0 = std::chrono::steady_clock::now();
  long long total = 0;
  for (const auto& scenario : scenarios) {
    for (const Scenario& sc : pairs) {
      LineReference line;  // thesis_line: x_d = t, y_d = 3
      std::vector<RunRow> rows;
      try {
        rows = runMonteCarlo(sc, line, spec, seeds, static_cast<int>(threads), [&](std::int64_t done) {
          if (done % 100 == 0 || done == seeds)
            std::fprintf(stderr, "\r%s %s: %lld / %lld", scenario.c_str(), sc.controllerName().c_str(),
                         static_cast<long long>(done), seeds);
        });
      } catch (const std::exception& e) {
        std::fprintf(stderr, "\n");
        return fail(e.what());
      }
      std::fprintf(stderr, "\n");
      csv += runsCsvLines(scenario, sc.controllerName(), rows);
      report += reportSection(scenario, sc.controllerName(), rows);
      total += seeds;
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Both written beside their names first, then renamed: no half-written pair under the real names.
  for (const auto& file :
       {std::make_pair(output + "/runs.csv", &csv), std::make_pair(output + "/report.md", &report)}) {
    std::ofstream f(file.first + ".tmp");
    f << *file.second;
    f.close();
    if (!f.good()) return fail("cannot write " + file.first + ".tmp");
  }
  for (const char* name : {"/runs.csv", "/report.md"})
    if (std::rename((output + name + ".tmp").c_str(), (output + name).c_str()) != 0)
      return fail("cannot rename " + output + name + ".tmp");
  std::printf("benchmark: %lld runs in %.2f s wall (%.2f ms per run, %s threads); %s/runs.csv, %s/report.md\n", total,
              wall, 1e3 * wall / static_cast<double>(total), threads == 0 ? "all" : std::to_string(threads).c_str(),
              output.c_str(), output.c_str());
  return 0;
}
