// Monte-Carlo runner: one scenario and controller pair over N seeded runs,
// each run drawing its plant mismatch, disturbance amplitude and phase, noise seed and start pose from
// stated distributions, run in parallel, with per-run rows and summary statistics.
//
// Reproducibility: run i's k-th draw is splitmix64(splitmix64(splitmix64(base_seed) + i) + k), its top
// 53 bits mapped to [0, 1) (k: 0 mass, 1 inertia, 2 amplitude, 3 phase, 4 noise seed (>> 33: the seed parameter is a
// 31-bit int), 5-7 start x, y, theta offsets, 8 the sensors' seed (>> 33, as 4; used by scenarios with sensors in the
// loop, runner.h)), a counter-based generator, so a run depends on (base_seed, i) only: the
// rows are bit-identical whatever the thread count and order, and any run can be repeated alone from its row.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/evaluation/seed_metrics.h"
#include "sowing_robot/core/planning/sine_reference.h"
#include "sowing_robot/core/simulation/field_run.h"
#include "sowing_robot/core/simulation/metrics.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {
namespace core {

/// A uniform distribution on [lo, hi] (lo == hi: that value).
struct Uniform {
  double lo = 0.0, hi = 0.0;
  double at(double u01) const { return lo + (hi - lo) * u01; }
};

/// What is drawn per run, and how success is judged. Defaults: around the thesis line scenario.
/// See MonteCarloSpec::rule.
enum class SuccessRule { tracking, sown };

struct MonteCarloSpec {
  std::uint64_t base_seed = 1;
  Uniform mass_scale{0.8, 1.5};           ///< true m0 / nominal
  Uniform inertia_scale{0.8, 1.5};        ///< true I0 / nominal (drawn independently of the mass)
  Uniform amplitude{0.0, 2.0};            ///< sinusoidal wheel-torque disturbance A [N·m] (Fig 5.9 uses 1)
  Uniform phase{0.0, 6.283185307179586};  ///< its phase [rad] (the plant's clock starts at phase / w)
  double noise_std = 0.1;                 ///< wheel-torque noise [N·m]; its seed is drawn per run
  Uniform start_dx{-0.5, 0.5};            ///< added to the scenario's start x [m]
  Uniform start_dy{-0.5, 0.5};            ///< added to the start y [m]
  Uniform start_dtheta{-0.3, 0.3};        ///< added to the start heading [rad]
  double settle_time = 15.0;              ///< success is judged from here to the end [s]
  double cross_track_threshold = 0.05;    ///< success (rule tracking): |e_y| below this after settle_time [m]
  /// How a run's success is judged beyond "not diverged, no contact, finished": tracking (|cross-track| below the
  /// threshold from settle_time on, the thesis's figure) or sown (the seed record: every row sown, the spacing and
  /// the line kept, the slip and the seed map within bounds). Default: sown for tracks with rows (field, line),
  /// tracking for the sine track, which has none.
  SuccessRule rule = SuccessRule::sown;
  double min_sown_share = 0.98;        ///< rule sown: each row's sown share outside detour stretches at least this
  double min_quality_of_feed = 95.0;   ///< rule sown: ISO 7256-1 quality of feed at least this [%]
  double max_seed_lateral_p95 = 0.05;  ///< rule sown: p95 of the seeds' offset from their row's line [m]
  double max_map_error_rms = 0.04;     ///< rule sown: RMS of |believed - true seed position| [m]
  /// rule sown, traction plant: share of the run either wheel slips beyond twice the friction peak's slip, at most.
  double max_high_slip_share = 0.05;

  std::string validate() const;
};

/// "tracking", "sown".
const char* successRuleName(SuccessRule r);
/// The rule's one-line statement for the report.
std::string describeSuccessRule(const MonteCarloSpec& spec);

/// What run `index` draws (the CSV's drawn columns).
struct RunDraw {
  std::int64_t index = 0;
  double mass_scale = 1.0, inertia_scale = 1.0, amplitude = 0.0, phase = 0.0;
  std::uint64_t noise_seed = 0;
  double start_x = 0.0, start_y = 0.0, start_theta = 0.0;
  std::uint64_t sensor_seed = 0;  ///< draw 8: sensors/seed of a scenario with sensors (BenchScenario::realism)
};
RunDraw drawRun(const MonteCarloSpec& spec, const Scenario& base, std::int64_t index);
/// The scenario run `draw` stands for (base with the draw applied).
Scenario applyDraw(const Scenario& base, const MonteCarloSpec& spec, const RunDraw& draw);

/// One run's row.
struct RunRow {
  RunDraw draw;
  std::array<AxisMetrics, AXIS_COUNT> metrics{};
  double effort = 0.0;             ///< integral of tau_r^2 + tau_l^2 [N^2·m^2·s]
  double chattering = 0.0;         ///< total variation sum |delta tau_r| + |delta tau_l| [N·m]
  double time_at_limit = 0.0;      ///< time with either torque clipped [s]
  double worst_cross_track = 0.0;  ///< max |e_y| after settle_time [m]
  double final_cross_track = 0.0;  ///< |e_y| at the end [m]
  std::size_t contacts = 0;        ///< body contacts with obstacles (field scenarios; 0 without obstacles)
  double min_clearance = 0.0;      ///< smallest body clearance [m] (NaN without obstacles)
  /// Field tracks: distance of the axle from the reference's last pose at the end [m] (NaN otherwise).
  double end_distance = std::numeric_limits<double>::quiet_NaN();
  bool diverged = false;
  bool success = false;
  std::string failure;  ///< why not a success ("" on success): diverged, contact, not finished, cross-track,
                        ///< or "no traction at (x y): why" (traction control on; one line, no commas)
  /// Signed cross-track error sampled every envelope period from t = 0 (runBenchmark only; empty otherwise).
  std::vector<double> cross_track_series;
  /// A scenario with BenchScenario::realism (estimated_bench.h): the columns below are its (NaN otherwise).
  bool realism = false;
  double max_slip = std::numeric_limits<double>::quiet_NaN();  ///< largest |slip ratio| (0 without traction)
  /// Share of the run either wheel's |slip ratio| was above twice the friction peak's (0 without traction).
  double high_slip_share = std::numeric_limits<double>::quiet_NaN();
  double tool_down_time = std::numeric_limits<double>::quiet_NaN();  ///< time the draft acted [s]
  /// Position error of the pose fed to the controllers against the truth, RMS and max over the run [m].
  double fed_error_rms = std::numeric_limits<double>::quiet_NaN();
  double fed_error_max = std::numeric_limits<double>::quiet_NaN();
  double odometry_error_max = std::numeric_limits<double>::quiet_NaN();  ///< the encoders' dead reckoning [m]
  long fixes_applied = 0, fixes_refused = 0;                             ///< feedback fused
  /// Hitch control: row length the tool missed while raised on slip [m], and the seeds that would have
  /// fallen there (that length over the seed drill's spacing). 0 without the hitch control.
  double unsown_distance = std::numeric_limits<double>::quiet_NaN();
  double seeds_unsown = std::numeric_limits<double>::quiet_NaN();
  /// The seed record's figures (seed_metrics.h): tracks with rows to sow; NaN (count 0) without. The registry's
  /// seed_figure entries read them (run_metrics.cpp).
  SeedFigures seed_figures;
  /// The seeds themselves, when the caller asked for them (RunExtras::keep_seeds; empty otherwise).
  std::vector<Seed> seed_record;
};

/// What one worker thread of a benchmark did: how many runs, and the CPU time its thread used
/// (CLOCK_THREAD_CPUTIME_ID). The benchmark prints them to tell why a speed-up from 1 to K threads falls
/// short of K: workers waiting (CPU below K x wall: the code) or cores of unequal speed (ms per run
/// unequal across workers: the machine; a VM's vCPUs may differ).
struct WorkerLoad {
  std::int64_t runs = 0;
  double cpu_seconds = 0.0;
};

/// Runs base (its controller pair, plant, timing) on `reference` for seeds 0..runs-1 with `threads`
/// threads (0: hardware concurrency). progress (optional) is called with the number of finished runs,
/// from whichever thread finished one (serialised). Throws std::invalid_argument for a bad spec or
/// scenario or runs < 1.
std::vector<RunRow> runMonteCarlo(const Scenario& base, const ReferenceSource& reference, const MonteCarloSpec& spec,
                                  std::int64_t runs, int threads = 0,
                                  const std::function<void(std::int64_t)>& progress = {});

/// What a benchmark scenario drives on (config/scenarios/*.yaml, track:).
enum class TrackKind { line, field, sine };

/// A scenario of the benchmark suite, ROS- and YAML-free (the loader in scenario_loader.h fills it from
/// config/scenarios/NAME.yaml): the closed loop (base: duration, rate, start, plant settings not drawn, the
/// controller pair and gains, set by the caller), what is drawn per run and how success is judged (spec), and
/// the track. A field scenario goes through the body: its footprint is checked against the obstacles every
/// period (ContactMonitor, as runField does) and any contact fails the run.
struct BenchScenario {
  std::string name;
  /// The evaluation set the scenario belongs to (docs/evaluation.md): "training" (the tuner sees it),
  /// "validation" (design choices are made on it) or "test" (reported, never looked at while designing).
  /// A scenario file's `set:` key; a scenario built in code is "validation" (it may have been looked at).
  std::string set = "validation";
  TrackKind track = TrackKind::line;
  Scenario base;
  MonteCarloSpec spec;
  double line_x0 = 0.0, line_v_r = 1.0, line_y = 3.0;  ///< track line: x_d = x0 + v_r t, y_d = y
  SineRowParams sine;                                  ///< track sine
  FieldParams field;                                   ///< track field (start_pose: the drawn start)
  std::vector<Obstacle> obstacles;                     ///< track field
  Footprint footprint = sowingRobotFootprint();        ///< track field: the body checked for contacts
  /// Track field: the run lasts base.duration plus the approach's extra time for the drawn start (as
  /// run_scenario --field), and is finished when the path has ended, the plan has no stop
  /// (AvoidanceStatus kOk) and the axle ends within this distance of the reference's last pose [m].
  double finish_tolerance = 0.5;
  double envelope_period = 0.1;  ///< period of RunRow::cross_track_series [s] (> 0)
  /// What else is in the loop (scenario keys traction:, sensors:, estimator:, feedback:): set, every run goes
  /// through runClosedLoop with this plant, these sensors (their seed replaced by the run's draw 8) and
  /// this feedback, scored on the truth (estimated_bench.h); unset, today's runClosedLoop.
  std::optional<LoopConfig> realism;
  /// Models the scenario declares it needs (`requires:`): each must be one of availableModels() and be
  /// switched on by the scenario ("wet_soil": realism with traction; "estimated_pose": realism with
  /// feedback odometry or fused). The extension point for models not built yet: a name announced but
  /// pending is refused by validate().
  std::vector<std::string> requires_models;

  std::string validate() const;
};

/// `bench` driven by the controller pair of `pair` (outer, inner, and the tables of every controller:
/// Kanayama, sliding mode, pure pursuit, PID): the scenario's timing, start and plant with those gains.
BenchScenario withController(BenchScenario bench, const Scenario& pair);

/// The models a scenario may require and the benchmark runs: "wet_soil", "estimated_pose".
const std::vector<std::string>& availableModels();

/// Runs `bench` (its base carries the controller pair) for seeds 0..runs-1 on `threads` threads (0: all
/// cores), as runMonteCarlo does (same draws, same thread-count independence), with the body contacts
/// and the finish check of field tracks, and the cross-track series for envelopes. Success: not
/// diverged, no contact, finished, and |cross-track| < threshold from settle_time on. Throws
/// std::invalid_argument for a bad scenario or runs < 1.
/// loads (optional): one WorkerLoad per worker thread, in the order the threads were started.
std::vector<RunRow> runBenchmark(const BenchScenario& bench, std::int64_t runs, int threads = 0,
                                 const std::function<void(std::int64_t)>& progress = {},
                                 std::vector<WorkerLoad>* loads = nullptr);

/// What runBenchmark checks before the first run (scenario, runs >= 1, every drawn run valid); throws
/// std::invalid_argument with one line.
void checkBenchmark(const BenchScenario& bench, std::int64_t runs);
/// One worker of runBenchmark: run(i) -> row i of `bench` (its own copy of the scenario and its own
/// references; call from one thread). runBenchmark's threads each run one; the MPI farm's ranks run the
/// same, so a row is the same bits wherever it ran.
std::function<RunRow(std::int64_t)> benchmarkWorker(const BenchScenario& bench);

/// A row as doubles (the draws' integers bit-cast, every metric of runMetrics() in its order, the failure
/// text one character per double) and back, exactly: what the MPI farm sends. unpackRow throws std::invalid_argument on
/// a malformed array.
std::vector<double> packRow(const RunRow& row);
RunRow unpackRow(const std::vector<double>& packed);

/// Quantiles over the runs of the cross-track series at each sample time (runs whose series is shorter
/// are left out there; a diverged run's non-finite samples count as +inf).
struct Envelope {
  double period = 0.1;
  std::vector<double> p05, p25, p50, p75, p95, max_abs;  ///< per sample time k * period
};
Envelope crossTrackEnvelope(const std::vector<RunRow>& rows, double period);
/// Tidy CSV of envelopes: header, then scenario, controller, t, p05, p25, p50, p75, p95, max_abs.
std::string envelopeCsvHeader();
std::string envelopeCsvLines(const std::string& scenario, const std::string& controller, const Envelope& e);

/// One metric over the runs. Diverged runs count: their +inf makes mean, std and worst +inf. NaN (a
/// figure a run does not have, e.g. a rise time never reached) is left out; all NaN gives NaN. p95 is
/// the nearest-rank 95th percentile.
struct Statistic {
  double mean = 0.0, std = 0.0, p95 = 0.0, worst = 0.0;
};
Statistic statistic(std::vector<double> values);

/// The names of the metrics of the report's per-metric table (run_metrics.h: report_table), in runs.csv's
/// order, and their values for a row.
const std::vector<std::string>& metricColumns();
std::vector<double> metricValues(const RunRow& row);

/// Tidy CSV: header line, then one line per row: scenario, set (BenchScenario::set: training, validation or
/// test; "" when the caller has none), controller, seed, the draws, every metric of runMetrics()
/// (run_metrics.h) of the group always, the failure. realism: then sensor_seed and the metrics of the group
/// realism (scenarios with sensors or traction; NaN or empty on rows without them).
std::string runsCsvHeader(bool realism = false);
std::string runsCsvLines(const std::string& scenario, const std::string& controller, const std::vector<RunRow>& rows,
                         bool realism = false, const std::string& set = "");
/// Markdown section for one scenario and controller: success rate with failure reasons, then per metric
/// (run_metrics.h: report_table) mean, std, p95 and worst.
std::string reportSection(const std::string& scenario, const std::string& controller, const std::vector<RunRow>& rows);
/// Markdown table header and one line of the overview (one line per scenario and controller): success rate,
/// failures, then the mean (or mean / p95) of each metric with an overview in run_metrics.h.
std::string summaryHeader();
std::string summaryLine(const std::string& scenario, const std::string& controller, const std::vector<RunRow>& rows);

}  // namespace core
}  // namespace sowing_robot
