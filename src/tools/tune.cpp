// tune: the PSO gain tuner on the command line, no ROS master. Same search and objective as the
// pso_tuner node (core::TuningSession = core::tuneGains in steps); threads without an MPI launcher, an MPI
// evaluation farm under mpirun / srun (rank 0 owns the search, checkpoint and output; every rank evaluates
// one particle at a time; results go back by particle index, so the gains do not depend on the number of
// ranks or threads, bit for bit).
//
//   tune --config FILE [--controller PAIR] [--output GAINS.yaml] [--checkpoint FILE [--resume]]
//        [--progress FILE.csv] [--threads N] [--stop-after K]
//   mpirun -np N tune --config FILE ...      (rosrun sowing_robot tune ... works the same)
//
// --config: config/tune.yaml's format (scenario_file/tune_config.h: the pso_tuner block of config/pso.yaml plus the
// base scenario; with a robust: block, robust tuning over a training set of benchmark scenarios,
// core/evaluation/robust_tuning.h, whose runs the farm hands out one by one). --controller: the pair tuned,
// in place of the file's pso_tuner/controller (scripts/tune_pairs --robust). --output: the gains YAML (default
// pso_tuner/output, else tuned_gains.yaml); its lines that can differ between two equal runs (date, wall time, ranks)
// start with "# run:". --checkpoint: the whole search state after every iteration (core/evaluation/checkpoint.h:
// written to FILE.tmp, then renamed);
// --resume continues from it (a missing file starts from the beginning; a damaged one or one of another
// setup is refused with one line); the result is that of an uninterrupted run. --progress: one CSV row per
// iteration (rewritten from the checkpoint's iteration on --resume). --stop-after K: stop after iteration K
// with exit code 3, as a kill would (tests). Exit codes: 0 done, 1 failed while running, 2 bad input,
// 3 stopped by --stop-after.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sowing_robot/cli/options.h"
#include "sowing_robot/cli/usage.h"
#include "sowing_robot/core/evaluation/checkpoint.h"
#include "sowing_robot/core/evaluation/tuning.h"
#include "sowing_robot/farm/farm.h"
#include "sowing_robot/scenario_file/tune_config.h"

using namespace sowing_robot;
using core::TuningCost;

#ifndef SOWING_SOURCE_DIR
#define SOWING_SOURCE_DIR "."
#endif

namespace {

const char* const kUsage =
    "usage: tune --config FILE [--controller PAIR] [--output GAINS.yaml] [--checkpoint FILE [--resume]]\n"
    "            [--progress FILE.csv] [--threads N] [--stop-after K]\n"
    "       mpirun -np N tune ...   (an MPI evaluation farm: the same gains, bit for bit, for any N)\n"
    "The PSO gain tuner without a ROS master (config/tune.yaml: pso_tuner keys and the base scenario;\n"
    "config/tuned/field/training.yaml: robust tuning over a training set of benchmark scenarios under a\n"
    "profile, robust/profile: a name in the package's config/profiles as benchmark --profile, or a file).\n\n"
    "Options:\n"
    "  --config FILE       the tuning set-up (required)\n"
    "  --controller PAIR   the pair tuned (outer+inner), in place of the file's pso_tuner/controller\n"
    "  --output FILE       the gains YAML (default: stdout)\n"
    "  --checkpoint FILE   written after every iteration (temporary file, then rename)\n"
    "  --resume            continue from --checkpoint\n"
    "  --progress FILE     one CSV row per iteration\n"
    "  --threads N         evaluation threads without MPI (0: all cores)\n"
    "  --stop-after K      stop after iteration K (tests of resume)\n"
    "  -h, --help          this text\n"
    "Bad input gives one line and exit 2. docs/farm.md: the farm, checkpoints, failures.\n";

std::string g(double v, const char* f = "%.6g") {
  char b[48];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

bool parseInt(const std::string& s, long long& out) {
  char* end = nullptr;
  out = std::strtoll(s.c_str(), &end, 10);
  return !s.empty() && *end == '\0';
}

struct Args {
  std::string config, controller, output, checkpoint, progress;
  bool resume = false;
  long long threads = -1, stop_after = -1;
};

/// "" or one line.
std::string parseArgs(int argc, char** argv, Args& a) {
  namespace cli = sowing_robot::cli;
  std::string threads, stop_after;
  cli::po::options_description options;
  options.add_options()("config", cli::po::value(&a.config))("controller", cli::po::value(&a.controller))(
      "output", cli::po::value(&a.output))("checkpoint", cli::po::value(&a.checkpoint))(
      "progress", cli::po::value(&a.progress))("threads", cli::po::value(&threads))(
      "stop-after", cli::po::value(&stop_after))("resume", cli::po::bool_switch(&a.resume));
  cli::po::variables_map vm;
  const std::string error = cli::parseOptions(
      argc, argv, {"tune", options, {}, [](const std::string& k) { return "missing value after " + k; }}, vm);
  if (!error.empty()) return error;
  // --threads N, --stop-after K: an integer >= 0 when given.
  auto count = [&vm](const std::string& key, const std::string& v, long long& n) -> std::string {
    if (!vm.count(key)) return "";
    long long value;
    if (!parseInt(v, value) || value < 0) return "--" + key + " needs an integer >= 0, not '" + v + "'";
    n = value;
    return "";
  };
  std::string e = count("threads", threads, a.threads);
  if (e.empty()) e = count("stop-after", stop_after, a.stop_after);
  if (!e.empty()) return e;
  if (a.config.empty()) return "--config FILE is required (see tune --help)";
  if (a.resume && a.checkpoint.empty()) return "--resume needs --checkpoint FILE";
  return "";
}

/// One task on any rank. One run on one scenario: request {bound, x...} -> {total, bounded, simulated} (a
/// particle's evaluation). Robust: request {k, x...} -> {cost of training run k} (one run of a particle's set).
farm::Payload evaluate(const core::GainObjective& problem, const farm::Payload& request) {
  const std::vector<double> x(request.begin() + 1, request.end());
  if (const auto* robust = dynamic_cast<const core::RobustTuningProblem*>(&problem))
    return {robust->runCost(x, static_cast<std::int64_t>(request.front()))};
  const TuningCost c = problem.evaluate(x, 0, request.front());
  return {c.total, c.bounded ? 1.0 : 0.0, c.simulated};
}

/// The objective the config describes: one run on its base scenario, or its robust training set.
std::unique_ptr<const core::GainObjective> makeObjective(const scenario_file::TuneConfig& cfg,
                                                         const core::ReferenceSource& reference, int threads) {
  if (cfg.isRobust()) return std::make_unique<core::RobustTuningProblem>(cfg.training, cfg.gains, cfg.robust, threads);
  return std::make_unique<core::TuningProblem>(cfg.base, reference, cfg.gains, cfg.objective, threads);
}

/// The MPI batch: a particle per task, or (robust) every run of every particle as its own task, so runs of
/// unequal length spread over the ranks; results land by index, so the costs do not depend on the ranks.
core::TuningBatch farmBatch(farm::Farm& farm, const core::GainObjective& problem) {
  const auto* robust = dynamic_cast<const core::RobustTuningProblem*>(&problem);
  return [&farm, &problem, robust](const std::vector<std::vector<double>>& x, const std::vector<double>& bounds,
                                   std::vector<TuningCost>& out) {
    const std::int64_t runs = robust ? robust->runCount() : 1;
    std::vector<double> run_costs(x.size() * static_cast<std::size_t>(runs));
    farm.run(
        static_cast<int>(run_costs.size()),
        [&](int task) {
          const auto j = static_cast<std::size_t>(task / runs);
          farm::Payload r{robust ? static_cast<double>(task % runs) : bounds[j]};
          r.insert(r.end(), x[j].begin(), x[j].end());
          return r;
        },
        [&problem](const farm::Payload& request) { return evaluate(problem, request); },
        [&](int task, const farm::Payload& r) {
          if (robust) {
            run_costs[static_cast<std::size_t>(task)] = r.at(0);
            return;
          }
          TuningCost& c = out[static_cast<std::size_t>(task)];
          c.total = r.at(0);
          c.bounded = r.at(1) != 0.0;
          c.simulated = r.at(2);
        });
    if (robust)
      for (std::size_t j = 0; j < x.size(); ++j)
        out[j] = robust->combine(std::vector<double>(run_costs.begin() + static_cast<std::ptrdiff_t>(j * runs),
                                                     run_costs.begin() + static_cast<std::ptrdiff_t>((j + 1) * runs)));
  };
}

bool writeAtomically(const std::string& path, const std::string& text, std::string& error) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    f.flush();
    if (!f) {
      error = "cannot write " + tmp;
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    error = "cannot rename " + tmp + " to " + path;
    return false;
  }
  return true;
}

/// The progress CSV kept up to (not including) iteration `from`; "" if it cannot be read.
std::string csvUpTo(const std::string& path, int from) {
  std::ifstream f(path);
  std::string line, out;
  bool header = true;
  while (std::getline(f, line)) {
    if (header) {
      header = false;
      continue;
    }
    long long it;
    if (parseInt(line.substr(0, line.find(',')), it) && it < from) out += line + "\n";
  }
  return out;
}

/// A worker rank: evaluates what rank 0 sends until rank 0 is done; the exit code.
int serveRank(farm::Farm& farm, const scenario_file::TuneConfig& cfg, const core::LineReference& reference) {
  const std::unique_ptr<const core::GainObjective> problem = makeObjective(cfg, reference, 1);
  long evaluations = 0;
  const char* die = std::getenv("SOWING_FARM_TEST_DIE_AFTER");  // test hook: this rank dies mid-run
  const long die_after = die ? std::atol(die) : -1;
  return farm.serve([&](const farm::Payload& request) {
    if (die_after >= 0 && evaluations++ >= die_after) std::raise(SIGKILL);
    return evaluate(*problem, request);
  })
             ? 0
             : 1;
}

/// --resume: the session continues from the checkpoint (a missing file: from the beginning). false, with
/// the error line printed, when the checkpoint is damaged or of another setup.
bool resumeSession(const Args& args, std::uint64_t fingerprint, const scenario_file::TuneConfig& cfg,
                   core::TuningSession& session) {
  if (::access(args.checkpoint.c_str(), F_OK) != 0) {
    std::fprintf(stderr, "tune: no checkpoint at %s yet: starting from the beginning\n", args.checkpoint.c_str());
    return true;
  }
  std::string body;
  const std::string e = core::readCheckpoint(args.checkpoint, "tune", fingerprint, body);
  if (!e.empty()) {
    std::fprintf(stderr, "tune: %s\n", e.c_str());
    return false;
  }
  try {
    session.restore(body);
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "tune: checkpoint %s: %s\n", args.checkpoint.c_str(), ex.what());
    return false;
  }
  std::fprintf(stderr, "tune: resuming from %s at iteration %d/%d (best cost %s)\n", args.checkpoint.c_str(),
               session.search().iteration(), cfg.pso.iterations, g(session.search().bestCost(), "%.9g").c_str());
  return true;
}

/// The progress CSV's header and, when resumed, the file's rows before the session's iteration.
std::string progressCsvStart(const Args& args, const scenario_file::TuneConfig& cfg,
                             const core::TuningSession& session) {
  std::string csv = "iteration,best_cost,evaluations,evaluations_cut,simulated_s,elapsed_s";
  for (const auto& b : cfg.gains) csv += "," + b.name;
  csv += "\n";
  if (session.search().iteration() > 0) csv += csvUpTo(args.progress, session.search().iteration());
  return csv;
}

/// The progress CSV's row of iteration `it`.
std::string progressCsvRow(int it, const scenario_file::TuneConfig& cfg, const core::TuningSession& session,
                           double elapsed) {
  std::string row = std::to_string(it) + "," + g(session.search().bestCost(), "%.17g") + "," +
                    std::to_string(static_cast<long>(it + 1) * cfg.pso.particles) + "," +
                    std::to_string(session.evaluationsCut()) + "," + g(session.simulatedSeconds(), "%.9g") + "," +
                    g(elapsed, "%.3f");
  for (double v : session.search().bestPosition()) row += "," + g(v, "%.17g");
  return row + "\n";
}

/// The gains searched with their bounds: "kx [0.1, 10], ky [0.1, 10], ...".
std::string searchedDims(const scenario_file::TuneConfig& cfg) {
  std::string dims;
  for (const auto& b : cfg.gains)
    dims += (dims.empty() ? "" : ", ") + b.name + " [" + g(b.lower) + ", " + g(b.upper) + "]";
  return dims;
}

/// How the search is run, the PSO and what is searched: rank 0 says what it starts.
struct SearchSetup {
  const Args& args;
  const scenario_file::TuneConfig& cfg;
  std::uint64_t fingerprint;  // of what the run was started with: checkpoints of anything else are refused
  std::string evaluators;     // the farm's ranks or "N thread(s)"
  std::string dims;           // searchedDims
};

/// Iterates the session to its end; after each iteration the checkpoint, the progress CSV and a log line.
/// false when --stop-after stopped it (exit 3); a failure ends the run on every rank (exit 1).
bool runSearch(farm::Farm& farm, const SearchSetup& setup, core::TuningSession& session, const core::TuningBatch& batch,
               std::chrono::steady_clock::time_point t0, int first) {
  const Args& args = setup.args;
  std::string csv = args.progress.empty() ? "" : progressCsvStart(args, setup.cfg, session);
  try {
    while (!session.finished()) {
      const int it = session.step(batch);
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::string error;
      if (!args.checkpoint.empty()) {
        error = core::writeCheckpoint(args.checkpoint, "tune", setup.fingerprint, session.toText());
        if (!error.empty()) throw std::runtime_error(error);
      }
      if (!args.progress.empty()) {
        csv += progressCsvRow(it, setup.cfg, session, elapsed);
        if (!writeAtomically(args.progress, csv, error)) throw std::runtime_error(error);
      }
      const double eta = elapsed / (it + 1 - first) * (setup.cfg.pso.iterations - it);
      std::fprintf(stderr, "tune: iteration %d/%d  best cost %.9g  elapsed %.2f s  ETA %.2f s\n", it,
                   setup.cfg.pso.iterations, session.search().bestCost(), elapsed, eta);
      if (args.stop_after >= 0 && it >= args.stop_after && !session.finished()) {
        std::fprintf(stderr, "tune: stopped after iteration %d (--stop-after); resume with --resume\n", it);
        return false;
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tune: stopped: %s; %s\n", e.what(),
                 args.checkpoint.empty() ? "no checkpoint kept (--checkpoint FILE)"
                                         : ("the last checkpoint is " + args.checkpoint + " (--resume)").c_str());
    farm.abort(1);
  }
  return true;
}

/// The gains file's "# cost:" line (robust: then its "# training:" lines), without the last line's newline.
std::string costComment(const scenario_file::TuneConfig& cfg) {
  std::string h;
  if (cfg.isRobust()) {
    h += "# cost: per training run min(2 ITAE(x+y+theta)/T^2, penalty) + penalty if not a success" +
         std::string(cfg.robust.max_slip_share < 1.0
                         ? " or beyond twice the peak's slip for more than " + g(cfg.robust.max_slip_share) + " of it"
                         : "") +
         " (core/evaluation/robust_tuning.h), " +
         std::string(cfg.robust.aggregate == core::RobustObjective::Aggregate::mean
                         ? "mean"
                         : "quantile " + g(cfg.robust.quantile)) +
         " over the runs, penalty " + g(cfg.robust.failure_penalty);
    // What the benchmark's report reads to tell held-out scenarios and draws from trained ones.
    for (const auto& t : cfg.training)
      h += "\n# training: " + t.bench.name + " runs " + std::to_string(t.runs) + " base_seed " +
           std::to_string(t.bench.spec.base_seed);
  } else {
    h += "# cost: " + std::string(core::costTypeName(cfg.objective.cost)) + " summed over x, y, theta";
    if (cfg.objective.torque_weight > 0) h += " + " + g(cfg.objective.torque_weight) + " * effort";
    if (cfg.objective.chattering_weight > 0) h += " + " + g(cfg.objective.chattering_weight) + " * chattering";
  }
  return h;
}

/// The gains file's comment lines: what was tuned, how, the costs, and (lines "# run:") when and on what.
std::string gainsHeader(const SearchSetup& setup, const core::TuningResult& r, double wall, int first) {
  const scenario_file::TuneConfig& cfg = setup.cfg;
  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S %z", std::localtime(&now));
  std::string h = "# Controller gains tuned offline by tune (PSO, thesis eqs 4.26-4.31, Table 5.4).\n";
  h += "# config: " + setup.args.config + "\n# scenario: " + cfg.scenarioText() + "\n";
  h += costComment(cfg);
  h += "\n# best_cost: " + core::yamlFloat(r.pso.best_cost) + "\n";
  h += "# initial_best_cost: " + core::yamlFloat(r.initial_best_cost) + "\n";
  h += "# pso: particles " + std::to_string(cfg.pso.particles) + ", iterations " + std::to_string(cfg.pso.iterations) +
       ", seed " + std::to_string(cfg.pso.seed) + ", evaluations " + std::to_string(r.pso.evaluations) + " (" +
       std::to_string(r.evaluations_cut) + " stopped early at their particle's best)\n";
  h += "# searched: " + setup.dims + "\n";
  h += "# run: " + std::string(date) + ", " + setup.evaluators + ", " + g(wall, "%.2f") + " s wall" +
       (first > 0 ? ", resumed at iteration " + std::to_string(first) : "") + "\n";
  return h;
}

/// The result on stdout: the costs, the gains, the file, and under MPI how the ranks were loaded.
void printResult(const farm::Farm& farm, const scenario_file::TuneConfig& cfg, const core::TuningResult& r, double wall,
                 const std::string& output) {
  std::string best;
  for (std::size_t d = 0; d < cfg.gains.size(); ++d)
    best += (d ? ", " : "") + cfg.gains[d].name + " " + g(r.best_gains[d], "%.5g");
  std::printf("tune: cost %.9g -> %.9g in %.2f s (%ld evaluations, %ld cut); %s\ntune: wrote %s\n", r.initial_best_cost,
              r.pso.best_cost, wall, r.pso.evaluations, r.evaluations_cut, best.c_str(), output.c_str());
  if (farm.active()) {
    const double eval = farm.evaluationSeconds();
    std::printf(
        "tune: farm: %d ranks, evaluation %.2f s summed over evaluators, rank 0 farm work %.4f s (%.3f %% of "
        "evaluation), evaluators busy %.1f %% of %d x wall\n",
        farm.size(), eval, farm.overheadSeconds(), eval > 0 ? 100.0 * farm.overheadSeconds() / eval : 0.0,
        wall > 0 ? 100.0 * eval / (wall * farm.size()) : 0.0, farm.size());
  }
}

int run(farm::Farm& farm, int argc, char** argv) {
  Args args;
  const std::string arg_error = parseArgs(argc, argv, args);
  if (!arg_error.empty()) {
    if (farm.root()) std::fprintf(stderr, "tune: %s\n", arg_error.c_str());
    return 2;
  }
  scenario_file::TuneConfig cfg;
  try {
    cfg = scenario_file::loadTuneConfig(args.config, args.controller, SOWING_SOURCE_DIR);
  } catch (const std::exception& e) {
    // Every rank reads the same file: rank 0 says what is wrong, the others leave quietly.
    if (farm.root()) std::fprintf(stderr, "tune: %s\n", e.what());
    return 2;
  }
  if (args.threads >= 0) cfg.pso.threads = static_cast<int>(args.threads);
  const core::LineReference reference = cfg.reference();
  if (!farm.root()) return serveRank(farm, cfg, reference);

  const std::string output = !args.output.empty() ? args.output : !cfg.output.empty() ? cfg.output : "tuned_gains.yaml";
  const int threads = farm.active() ? 1 : core::psoThreads(cfg.pso);
  std::unique_ptr<core::TuningSession> session;
  try {
    session = std::make_unique<core::TuningSession>(makeObjective(cfg, reference, threads), cfg.pso);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tune: %s: %s\n", args.config.c_str(), e.what());
    return 2;
  }
  // What the run was started with: the config's bytes, the scenario as read, and the initial swarm (PSO
  // parameters, bounds, seed). A checkpoint of anything else is refused.
  const SearchSetup setup{args, cfg,
                          core::fnv1a64("tune 1\n" + cfg.text + "\n" + cfg.scenarioText() + "\n" + session->toText()),
                          farm.active() ? farm.describe() : std::to_string(threads) + " thread(s)", searchedDims(cfg)};
  if (args.resume && !resumeSession(args, setup.fingerprint, cfg, *session)) return 2;

  std::fprintf(stderr, "tune: %s; %s\ntune: scenario %s\ntune: searching %s\n", setup.evaluators.c_str(),
               ("particles " + std::to_string(cfg.pso.particles) + ", iterations " +
                std::to_string(cfg.pso.iterations) + ", seed " + std::to_string(cfg.pso.seed))
                   .c_str(),
               cfg.scenarioText().c_str(), setup.dims.c_str());

  const core::TuningBatch batch = farm.active() ? farmBatch(farm, session->problem())
                                                : core::threadedTuningBatch(session->problem(), session->params());
  const auto t0 = std::chrono::steady_clock::now();
  const int first = session->search().iteration();
  if (!runSearch(farm, setup, *session, batch, t0, first)) return 3;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  farm.stop();

  const core::TuningResult r = session->result();
  if (!std::isfinite(r.pso.best_cost)) {
    std::fprintf(stderr, "tune: every run diverged (no finite cost); nothing written. Narrow the gain bounds.\n");
    return 1;
  }
  const core::Scenario tuned = session->problem().scenarioFor(r.best_gains);
  std::string error;
  if (!writeAtomically(output, gainsHeader(setup, r, wall, first) + core::gainsYaml(tuned, cfg.gains), error)) {
    std::fprintf(stderr, "tune: %s\n", error.c_str());
    return 1;
  }
  printResult(farm, cfg, r, wall, output);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  sowing_robot::cli::exitOnHelp(argc, argv, kUsage);  // before MPI: no rank, no farm for --help
  std::unique_ptr<farm::Farm> f;
  try {
    f = std::make_unique<farm::Farm>(&argc, &argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tune: cannot start MPI: %s\n", e.what());
    return 2;
  }
  return run(*f, argc, argv);
}
