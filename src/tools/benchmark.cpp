// benchmark: Monte-Carlo statistics of controller pairs over the scenario suite, in-process (no ROS master).
// Usage and options: kUsage below (benchmark --help).
// Scenarios are names in the scenario directory (default: the package's config/scenarios; `all` for every
// file there) or paths to scenario files; controllers are outer+inner pairs (kanayama|pure_pursuit|rpp +
// atsmc|tsmc|pid). A pair's gains come from TUNED_DIR/OUTER+INNER.yaml when that file exists (default the
// package's config/tuned, or a named profile's gains directory), else from the parameter tables' defaults; the
// report says which. --profile NAME reads a profile as sim.launch profile:=NAME does (scenario_file::resolveProfile).
// Writes DIR/runs.csv (one row per run: scenario, controller, seed, the values drawn, every metric, contacts,
// success and the failure reason), DIR/metrics.json (what each metric column is: core/evaluation/run_metrics.h,
// read by benchmark_plots), DIR/envelopes.csv (per scenario, controller and time: quantiles of the
// cross-track error over the runs) and DIR/report.md (overview, then per scenario and controller: success
// rate with reasons, mean, std, p95 and worst of every metric). The files do not depend on --threads.
// Everything is loaded and checked before the first run, and written only when every run is done: an unknown
// name, a seed count of 0, a scenario file with a typo or an unwritable DIR gives one error line, exit 2,
// and no report. A progress line goes to stderr.
//
// Under mpirun (or srun) the runs go to an MPI evaluation farm (farm/farm.h): every rank reads the
// same arguments and files, rank 0 hands out one run at a time to whichever rank is free (its own evaluation
// thread included) and writes the files; each rank runs core::benchmarkWorker, as the threads do, so the
// files are the same byte for byte for any number of ranks or threads. --threads is then ignored.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sowing_robot/cli/options.h"
#include "sowing_robot/cli/usage.h"
#include "sowing_robot/core/evaluation/benchmark.h"
#include "sowing_robot/core/evaluation/estimated_bench.h"
#include "sowing_robot/core/evaluation/run_metrics.h"
#include "sowing_robot/core/simulation/runner.h"
#include "sowing_robot/farm/farm.h"
#include "sowing_robot/scenario_file/scenario_loader.h"
#include "sowing_robot/scenario_file/scenario_sets.h"

using namespace sowing_robot::core;
namespace scenario_file = sowing_robot::scenario_file;

#ifndef SOWING_SOURCE_DIR
#define SOWING_SOURCE_DIR "."
#endif

namespace {
/// The protocol's scenarios (every set): what a test scenario is compared with, and where a robust tuning's
/// training scenarios are found by name.
const char* const kCatalogDir = SOWING_SOURCE_DIR "/config/scenarios";
}  // namespace

namespace {
const char* const kUsage =
    "usage: benchmark --seeds N --output DIR [--scenarios A,B] [--controllers X,Y] [--threads K]\n"
    "                 [--scenario-dir DIR] [--tuned-dir DIR] [--base-seed S] [--profile NAME|FILE]\n"
    "Monte-Carlo statistics of controller pairs over the scenario suite, in-process (no ROS master).\n"
    "Writes DIR/runs.csv, DIR/metrics.json (its metric columns: name, unit, meaning, aggregation),\n"
    "DIR/envelopes.csv and DIR/report.md (the same whatever --threads).\n\n"
    "Options:\n"
    "  --seeds N            seeded runs per scenario and controller (required, >= 1)\n"
    "  --output DIR         where the files go (required)\n"
    "  --scenarios A,B      names in the scenario directory, paths to scenario files, or `all` (default thesis_line)\n"
    "  --controllers X,Y    outer+inner pairs: kanayama|pure_pursuit|rpp + atsmc|tsmc|pid (default kanayama+atsmc)\n"
    "  --threads K          worker threads, 0 = all cores (default 0)\n"
    "  --scenario-dir DIR   default: the package's config/scenarios\n"
    "  --tuned-dir DIR      OUTER+INNER.yaml gains when present, else the tables' defaults (default config/tuned,\n"
    "                       or the profile's gains directory)\n"
    "  --base-seed S        overrides every scenario's base seed\n"
    "  --profile NAME|FILE  a set-up on top of every scenario file's blocks, as sim.launch profile:=NAME: a name\n"
    "                       in the package's config/profiles (field: the recommended drive train), whose gains\n"
    "                       config/tuned/NAME/ come with it (unless --tuned-dir), or a profile file's path\n"
    "  -h, --help           this text\n"
    "A bad request (unknown name, --seeds 0, a scenario file with a typo, an unwritable DIR) gives one error\n"
    "line, exit 2, and no report.\n";

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

bool g_quiet = false;  // MPI worker ranks: rank 0 reports (every rank reads the same input)

int fail(const std::string& message) {
  if (!g_quiet) std::fprintf(stderr, "benchmark: %s\n", message.c_str());
  return 2;
}

bool parseInteger(const char* text, long long& value) {
  char* end = nullptr;
  value = std::strtoll(text, &end, 10);
  return end != text && *end == '\0';
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

std::string uniform(const Uniform& u) { return u.lo == u.hi ? num(u.lo) : "U(" + num(u.lo) + ", " + num(u.hi) + ")"; }

const char* trackName(TrackKind t) { return t == TrackKind::line ? "line" : t == TrackKind::field ? "field" : "sine"; }

/// One paragraph: what the scenario draws and how it is judged.
std::string describe(const BenchScenario& b) {
  const MonteCarloSpec& s = b.spec;
  std::string out = "- **" + b.name + "** [" + b.set + "] (" + trackName(b.track) + ", " + num(b.base.duration) + " s" +
                    (b.track == TrackKind::field ? " + the approach's extra time" : "") + " at " +
                    num(1e9 / static_cast<double>(b.base.control_period_ns)) + " Hz, start (" + num(b.base.start.x) +
                    ", " + num(b.base.start.y) + ", " + num(b.base.start.theta) + ")";
  if (b.track == TrackKind::field)
    out += ", " + std::to_string(b.obstacles.size()) + " obstacles, body contacts counted";
  out += "): base seed " + std::to_string(s.base_seed) + "; mass x" + uniform(s.mass_scale) + ", inertia x" +
         uniform(s.inertia_scale) + ", disturbance A " + uniform(s.amplitude) + " N·m at w " +
         num(b.base.disturbance.frequency) + " rad/s, phase " + uniform(s.phase) + " rad, wheel noise std " +
         num(s.noise_std) + " N·m (seed drawn), start + (" + uniform(s.start_dx) + ", " + uniform(s.start_dy) + ", " +
         uniform(s.start_dtheta) + "); success: " + describeSuccessRule(s);
  if (b.track == TrackKind::field) out += ", axle within " + num(b.finish_tolerance) + " m of the path's end";
  return out + ".\n";
}

bool writeAll(const std::string& dir, const std::vector<std::pair<std::string, const std::string*>>& files,
              std::string& error) {
  // Each written beside its name first, then renamed: no half-written set under the real names.
  for (const auto& f : files) {
    std::ofstream out(dir + "/" + f.first + ".tmp");
    out << *f.second;
    out.close();
    if (!out.good()) {
      error = "cannot write " + dir + "/" + f.first + ".tmp";
      return false;
    }
  }
  for (const auto& f : files)
    if (std::rename((dir + "/" + f.first + ".tmp").c_str(), (dir + "/" + f.first).c_str()) != 0) {
      error = "cannot rename " + dir + "/" + f.first + ".tmp";
      return false;
    }
  return true;
}

// Worker t's runs and CPU time summed over the scenario x controller batches (each batch starts its
// threads in the same order).
void addLoads(const std::vector<WorkerLoad>& batch, std::vector<WorkerLoad>& total) {
  if (total.size() < batch.size()) total.resize(batch.size());
  for (std::size_t t = 0; t < batch.size(); ++t) {
    total[t].runs += batch[t].runs;
    total[t].cpu_seconds += batch[t].cpu_seconds;
  }
}

// "benchmark: workers: 512 runs, 2.31 s CPU, 4.51 ms per run | 488 runs, ...; CPU 97 % of 2 x wall".
// Why a speed-up from 1 to K threads falls short of K: CPU well below K x wall means idle workers (the
// code's doing); unequal ms per run means cores of unequal speed (the machine's: a VM's vCPUs may differ).
std::string loadLine(const std::vector<WorkerLoad>& loads, double wall) {
  std::string line = "benchmark: workers:";
  double cpu = 0.0;
  for (std::size_t t = 0; t < loads.size(); ++t) {
    const WorkerLoad& w = loads[t];
    char part[128];
    std::snprintf(part, sizeof part, "%s %lld runs, %.2f s CPU, %.2f ms per run", t == 0 ? "" : " |",
                  static_cast<long long>(w.runs), w.cpu_seconds,
                  w.runs > 0 ? 1e3 * w.cpu_seconds / static_cast<double>(w.runs) : 0.0);
    line += part;
    cpu += w.cpu_seconds;
  }
  char tail[96];
  std::snprintf(tail, sizeof tail, "; CPU %.0f %% of %zu x wall",
                wall > 0 && !loads.empty() ? 100.0 * cpu / (wall * loads.size()) : 0.0, loads.size());
  return line + tail;
}

/// The command line, as given (defaults where an option is absent).
struct Options {
  std::vector<std::string> scenario_names{"thesis_line"}, controllers{"kanayama+atsmc"};
  long long seeds = -1, threads = 0, base_seed = -1;
  std::string output, scenario_dir = SOWING_SOURCE_DIR "/config/scenarios",
                      tuned_dir = SOWING_SOURCE_DIR "/config/tuned", profile;
  bool tuned_dir_given = false;
  scenario_file::ProfileFiles profile_files;  // what --profile names (resolveProfile)
};

/// Reads and checks the options; false (with `exit_code` and the error line printed) on a bad request.
bool parseOptions(int argc, char** argv, Options& o, int& exit_code) {
  namespace cli = sowing_robot::cli;
  std::string controllers, scenarios;
  cli::po::options_description options;
  options.add_options()("controllers", cli::po::value(&controllers))("scenarios", cli::po::value(&scenarios))(
      "output", cli::po::value(&o.output))("scenario-dir", cli::po::value(&o.scenario_dir))(
      "tuned-dir", cli::po::value(&o.tuned_dir))("seeds", cli::po::value<std::string>())(
      "threads", cli::po::value<std::string>())("base-seed", cli::po::value<std::string>())("profile",
                                                                                            cli::po::value(&o.profile));
  cli::po::variables_map vm;
  const std::string parse_error = cli::parseOptions(
      argc, argv, {"benchmark", options, {}, [](const std::string& a) { return "missing value after " + a; }}, vm);
  if (!parse_error.empty()) {
    exit_code = fail(parse_error);
    return false;
  }
  if (vm.count("controllers")) o.controllers = splitComma(controllers);
  if (vm.count("scenarios")) o.scenario_names = splitComma(scenarios);
  o.tuned_dir_given = vm.count("tuned-dir") > 0;
  for (const auto& [key, n] :
       {std::pair<const char*, long long*>{"seeds", &o.seeds}, {"threads", &o.threads}, {"base-seed", &o.base_seed}}) {
    if (!vm.count(key)) continue;
    const std::string& v = vm[key].as<std::string>();
    if (!parseInteger(v.c_str(), *n)) {
      exit_code = fail("--" + std::string(key) + " needs an integer, not '" + v + "'");
      return false;
    }
  }
  std::string error;
  if (o.seeds < 1)
    error = o.seeds == -1 ? "--seeds N is required" : "--seeds must be >= 1";
  else if (o.threads < 0)
    error = "--threads must be >= 0 (0: all cores)";
  else if (o.base_seed < -1)
    error = "--base-seed must be >= 0";
  else if (o.output.empty())
    error = "--output DIR is required";
  if (!error.empty()) {
    exit_code = fail(error);
    return false;
  }
  if (!o.profile.empty()) {
    try {
      o.profile_files = scenario_file::resolveProfile(o.profile, SOWING_SOURCE_DIR);
    } catch (const std::exception& e) {
      exit_code = fail(e.what());
      return false;
    }
    // A named profile brings the gains tuned for it, as sim.launch profile:=NAME; --tuned-dir still wins.
    if (!o.tuned_dir_given && !o.profile_files.gains_dir.empty()) o.tuned_dir = o.profile_files.gains_dir;
  }
  if (o.scenario_names.size() == 1 && o.scenario_names[0] == "all")
    o.scenario_names = scenario_file::scenarioNames(o.scenario_dir);
  return true;
}

/// The scenarios and controller pairs the options name, loaded and checked before the first run.
struct Suite {
  std::vector<BenchScenario> scenarios;
  /// The same scenarios read without the profile (the run's base seed in place): their content, which the
  /// evaluation protocol compares (scenario_sets.h).
  std::vector<BenchScenario> plain;
  std::vector<scenario_file::CatalogEntry> catalog;  // the package's config/scenarios, every set
  std::vector<Scenario> pairs;
  std::vector<std::string> gains_source;  // per pair: the tuned file its gains come from, or why the defaults
};

/// Throws on the first unknown name or bad file (scenarios first, then controllers, in the given order).
Suite loadSuite(const Options& o) {
  Suite suite;
  suite.catalog = scenario_file::scenarioCatalog(kCatalogDir);
  for (const auto& name : o.scenario_names) {
    suite.scenarios.push_back(scenario_file::loadScenario(name, o.scenario_dir, o.profile_files.file));
    suite.plain.push_back(scenario_file::loadScenario(name, o.scenario_dir));
    if (o.base_seed >= 0)
      for (auto* b : {&suite.scenarios.back(), &suite.plain.back()})
        b->spec.base_seed = static_cast<std::uint64_t>(o.base_seed);
    // A test scenario whose content a training or validation scenario holds would be reported as a blind test
    // while it is not one: refused, naming what it shares (docs/evaluation.md).
    const auto overlaps = scenario_file::testOverlaps(suite.plain.back(), suite.catalog);
    if (!overlaps.empty()) {
      std::string list;
      for (const auto& l : overlaps) list += (list.empty() ? "" : "; ") + l;
      throw std::invalid_argument("test scenario " + suite.plain.back().name +
                                  " is not held out: its content overlaps " + list +
                                  " (a test scenario needs a world, layout and soil, and draws of its own; "
                                  "docs/evaluation.md)");
    }
  }
  for (const auto& c : o.controllers) {
    Scenario sc;
    const std::string e = parseControllerPair(c, sc.outer, sc.inner, sc.sliding.adaptive);
    if (!e.empty()) throw std::invalid_argument(e);
    const std::string tuned = scenario_file::tunedGainsFile(o.tuned_dir, sc);
    if (!tuned.empty()) scenario_file::applyTunedGains(tuned, sc);
    suite.gains_source.push_back(tuned.empty() ? "the parameter tables' defaults (no " + sc.controllerName() +
                                                     ".yaml in " + o.tuned_dir + ")"
                                               : tuned);
    suite.pairs.push_back(sc);
  }
  return suite;
}

/// Every scenario x controller batch, in the files' order: the runs' (batch, seed) is what the farm sends.
std::vector<BenchScenario> batchesOf(const Suite& suite) {
  std::vector<BenchScenario> batches;
  for (const BenchScenario& scenario : suite.scenarios) {
    for (const Scenario& pair : suite.pairs) {
      batches.push_back(withController(scenario, pair));
    }
  }
  return batches;
}

/// Makes DIR if missing and checks that a file can be written into it (before any run).
bool canWriteInto(const std::string& dir) {
  ::mkdir(dir.c_str(), 0777);  // may exist; the writes below report a real failure
  {
    std::ofstream probe(dir + "/.benchmark_probe");
    if (!probe.good()) return false;
  }
  std::remove((dir + "/.benchmark_probe").c_str());
  return true;
}

/// The report's line on --profile ("" without one): its file, and whether the gains are the ones tuned for it.
std::string profileLine(const Options& o) {
  if (o.profile.empty()) return "";
  const scenario_file::ProfileFiles& p = o.profile_files;
  std::string line = "Profile: `" + o.profile + "`";
  if (p.file == o.profile)
    line += " (a file, no gains of its own)";
  else if (p.gains_dir.empty())
    line += " (" + p.file + "), no gains of its own (no config/tuned/" + o.profile + "/)";
  else if (o.tuned_dir_given)
    line += " (" + p.file + "), its gains (" + p.gains_dir + ") replaced by --tuned-dir";
  else
    line += " (" + p.file + "), with its gains (" + p.gains_dir + ")";
  return line + ".\n\n";
}

/// The report's paragraph on the evaluation sets (docs/evaluation.md): which scenario is in which, and the content
/// digest of each (equal digests: equal content).
std::string setsParagraph(const Suite& suite) {
  std::string out =
      "Evaluation sets (docs/evaluation.md; test: reported, never looked at while designing; validation: "
      "the profile's and the estimator's design choices were made on it; training: the tuner's):\n\n";
  for (const std::string& set : scenario_file::scenarioSets()) {
    std::string names;
    for (const auto& b : suite.plain)
      if (b.set == set)
        names += std::string(names.empty() ? "" : ", ") + b.name + " (content " +
                 scenario_file::fingerprintOf(b).digest() + ")";
    if (!names.empty()) out += "- " + set + ": " + names + "\n";
  }
  return out;
}

/// report.md up to its overview: the profile, how many runs, where each pair's gains come from (with what a
/// robust tuning never saw), and what each scenario draws.
std::string reportHead(const Suite& suite, const Options& o) {
  const long long seeds = o.seeds;
  std::string report =
      "# Controller benchmark\n\n" + std::to_string(seeds) +
      " seeded runs per scenario and controller, in-process (`benchmark`, core/evaluation/benchmark.h); every "
      "run can be repeated alone from its row of runs.csv.\n\n" +
      profileLine(o) + "Gains:\n\n";
  std::string held_out;  // for gains from a robust tuning: which scenarios and draws it never saw
  for (std::size_t p = 0; p < suite.pairs.size(); ++p) {
    report += "- " + suite.pairs[p].controllerName() + ": " + suite.gains_source[p] + "\n";
    const auto training = scenario_file::trainingOf(suite.gains_source[p]);
    if (training.empty()) continue;
    held_out += "- " + suite.pairs[p].controllerName() + ", trained on";
    for (const auto& t : training)
      held_out += " " + t.scenario + " (runs 0-" + std::to_string(t.runs - 1) + ", base seed " +
                  std::to_string(t.base_seed) + ")";
    held_out += ":";
    for (const auto& b : suite.plain)
      held_out +=
          " " + b.name + " " + scenario_file::heldOutVerdict(training, b, seeds, suite.catalog, kCatalogDir) + ";";
    held_out += "\n";
  }
  if (!held_out.empty())
    report += "\nTraining and held-out data (robust-tuned gains; judged by content, not by name):\n\n" + held_out;
  report += "\n" + setsParagraph(suite);
  report += "\nScenarios:\n\n";
  for (const auto& b : suite.scenarios) report += describe(b) + describeRealism(b);
  return report;
}

/// The progress line on stderr: every 10 runs on a terminal (rewritten in place), else once per batch.
class Progress {
 public:
  Progress(long long seeds, long long total)
      : tty_(::isatty(STDERR_FILENO) != 0), t0_(std::chrono::steady_clock::now()), seeds_(seeds), total_(total) {}

  /// The callback for one batch's runs (`done` of its seeds finished).
  std::function<void(std::int64_t)> forBatch(const std::string& scenario, const std::string& controller) const {
    return [this, scenario, controller](std::int64_t done) {
      if (!tty_ && done != seeds_) return;
      if (tty_ && done % 10 != 0 && done != seeds_) return;
      const double wall = seconds();
      const double frac = static_cast<double>(finished_ + done) / static_cast<double>(total_);
      std::fprintf(stderr, "%s%s / %s: %lld/%lld runs; all %lld/%lld, %.0f s, about %.0f s left%s", tty_ ? "\r" : "",
                   scenario.c_str(), controller.c_str(), static_cast<long long>(done), seeds_, finished_ + done, total_,
                   wall, frac > 0 ? wall * (1.0 - frac) / frac : 0.0, tty_ ? "   " : "\n");
    };
  }
  void batchDone() { finished_ += seeds_; }
  /// Ends the line a terminal rewrites in place.
  void endLine() const {
    if (tty_) std::fprintf(stderr, "\n");
  }
  /// Wall time since the runs began.
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }

 private:
  bool tty_;
  std::chrono::steady_clock::time_point t0_;
  long long seeds_, total_, finished_ = 0;
};

/// The rows of one batch's seeds: from the farm under MPI, else from runBenchmark's threads (their loads in
/// `loads`). Throws what a run throws.
std::vector<RunRow> runBatch(sowing_robot::farm::Farm& farm, const sowing_robot::farm::Compute& compute, std::size_t k,
                             const BenchScenario& b, const Options& o,
                             const std::function<void(std::int64_t)>& progress, std::vector<WorkerLoad>& loads) {
  if (!farm.active()) return runBenchmark(b, o.seeds, static_cast<int>(o.threads), progress, &loads);
  checkBenchmark(b, o.seeds);  // before any run, as runBenchmark does
  std::vector<RunRow> rows(static_cast<std::size_t>(o.seeds));
  std::int64_t done = 0;
  farm.run(
      static_cast<int>(o.seeds),
      [k](int i) {
        return sowing_robot::farm::Payload{static_cast<double>(k), static_cast<double>(i)};
      },
      compute,
      [&](int i, const sowing_robot::farm::Payload& packed) {
        rows[static_cast<std::size_t>(i)] = unpackRow(packed);
        progress(++done);
      });
  return rows;
}

/// The four files' texts, filled batch by batch in the files' order.
struct Outputs {
  std::string csv, envelopes, summary, sections;
  std::vector<WorkerLoad> loads;  // per worker thread, over all batches
};

/// Runs every batch into `out`; on a failed run, the error line and exit 2 (every rank of a farm ends).
bool runAll(sowing_robot::farm::Farm& farm, const sowing_robot::farm::Compute& compute,
            const std::vector<BenchScenario>& batches, const Options& o, bool realism, Progress& progress, Outputs& out,
            int& exit_code) {
  for (std::size_t k = 0; k < batches.size(); ++k) {
    const BenchScenario& b = batches[k];
    const std::string name = b.base.controllerName();
    std::vector<RunRow> rows;
    std::vector<WorkerLoad> batch_loads;
    try {
      rows = runBatch(farm, compute, k, b, o, progress.forBatch(b.name, name), batch_loads);
    } catch (const std::exception& e) {
      progress.endLine();
      if (farm.active()) {
        fail(b.name + " / " + name + ": " + e.what());
        farm.abort(2);
      }
      exit_code = fail(b.name + " / " + name + ": " + e.what());
      return false;
    }
    progress.batchDone();
    addLoads(batch_loads, out.loads);
    out.csv += runsCsvLines(b.name, name, rows, realism, b.set);
    out.envelopes += envelopeCsvLines(b.name, name, crossTrackEnvelope(rows, b.envelope_period));
    out.summary +=
        summaryLine(b.name + " [" + b.set + "]", name, rows);  // the set beside the name: test figures stand out
    out.sections += reportSection(b.name, name, rows);
  }
  return true;
}

/// The closing lines on stdout: runs and wall time, then how the farm's ranks or the threads were loaded.
void printTotals(const sowing_robot::farm::Farm& farm, const Options& o, long long total, double wall,
                 const std::vector<WorkerLoad>& loads) {
  if (farm.active()) {
    const double eval = farm.evaluationSeconds();
    std::printf("benchmark: %lld runs in %.2f s wall (%.2f ms per run, %s); %s/runs.csv, envelopes.csv, report.md\n",
                total, wall, 1e3 * wall / static_cast<double>(total), farm.describe().c_str(), o.output.c_str());
    std::printf(
        "benchmark: farm: evaluation %.2f s summed over %d evaluators, rank 0 farm work %.4f s (%.3f %% of "
        "evaluation), evaluators busy %.1f %% of %d x wall\n",
        eval, farm.size(), farm.overheadSeconds(), eval > 0 ? 100.0 * farm.overheadSeconds() / eval : 0.0,
        wall > 0 ? 100.0 * eval / (wall * farm.size()) : 0.0, farm.size());
    return;
  }
  // The worker threads that ran (--threads 0 is all cores; never more workers than batches of runs).
  const std::size_t nworkers = loads.size();
  std::printf(
      "benchmark: %lld runs in %.2f s wall (%.2f ms per run, %zu thread%s%s); %s/runs.csv, envelopes.csv, report.md\n",
      total, wall, 1e3 * wall / static_cast<double>(total), nworkers, nworkers == 1 ? "" : "s",
      o.threads == 0 ? ", all cores" : "", o.output.c_str());
  std::printf("%s\n", loadLine(loads, wall).c_str());
}

}  // namespace

int run(sowing_robot::farm::Farm& farm, int argc, char** argv);

int main(int argc, char** argv) {
  sowing_robot::cli::exitOnHelp(argc, argv, kUsage);  // before MPI: no rank, no farm for --help
  std::unique_ptr<sowing_robot::farm::Farm> farm;
  try {
    farm = std::make_unique<sowing_robot::farm::Farm>(&argc, &argv);
  } catch (const std::exception& e) {
    return fail(std::string("cannot start MPI: ") + e.what());
  }
  g_quiet = !farm->root();
  return run(*farm, argc, argv);
}

int run(sowing_robot::farm::Farm& farm, int argc, char** argv) {
  Options o;
  int exit_code = 0;
  if (!parseOptions(argc, argv, o, exit_code)) return exit_code;
  Suite suite;
  try {
    suite = loadSuite(o);
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  const std::vector<BenchScenario> batches = batchesOf(suite);
  // One run on any rank: {batch, seed} -> the packed row, by each batch's benchmarkWorker (made on first use).
  std::vector<std::function<RunRow(std::int64_t)>> workers(batches.size());
  const sowing_robot::farm::Compute compute = [&](const sowing_robot::farm::Payload& request) {
    const auto k = static_cast<std::size_t>(request.at(0));
    if (!workers.at(k)) workers[k] = benchmarkWorker(batches[k]);
    return packRow(workers[k](static_cast<std::int64_t>(request.at(1))));
  };
  if (!farm.root()) return farm.serve(compute) ? 0 : 1;
  if (!canWriteInto(o.output)) return fail("cannot write into " + o.output);

  // Scenarios with sensors, traction or an estimate in the loop add their columns (estimated_bench.h); without
  // one, runs.csv is today's, byte for byte.
  bool realism = false;
  for (const auto& b : suite.scenarios) realism = realism || b.realism.has_value();
  Outputs out;
  out.csv = runsCsvHeader(realism);
  out.envelopes = envelopeCsvHeader();
  out.summary = summaryHeader();
  std::string report = reportHead(suite, o);

  const long long total = o.seeds * static_cast<long long>(suite.scenarios.size() * suite.pairs.size());
  Progress progress(o.seeds, total);
  if (!runAll(farm, compute, batches, o, realism, progress, out, exit_code)) return exit_code;
  progress.endLine();
  report += "\n## Overview\n\n" + out.summary + "\n" + out.sections;
  const double wall = progress.seconds();
  std::string error;
  const std::string metrics = runMetricsJson();
  if (!writeAll(o.output,
                {{"runs.csv", &out.csv},
                 {"metrics.json", &metrics},
                 {"envelopes.csv", &out.envelopes},
                 {"report.md", &report}},
                error))
    return fail(error);
  farm.stop();
  printTotals(farm, o, total, wall, out.loads);
  return 0;
}
