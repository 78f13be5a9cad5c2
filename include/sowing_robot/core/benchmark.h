// Monte-Carlo runner (issue 17 item 3, first part): one scenario and controller pair over N seeded runs,
// each run drawing its plant mismatch, disturbance amplitude and phase, noise seed and start pose from
// stated distributions, run in parallel, with per-run rows and summary statistics.
//
// Reproducibility: run i's k-th draw is splitmix64(splitmix64(splitmix64(base_seed) + i) + k), its top
// 53 bits mapped to [0, 1) (k: 0 mass, 1 inertia, 2 amplitude, 3 phase, 4 noise seed (>> 33: the seed parameter is a
// 31-bit int), 5-7 start x, y, theta offsets), a counter-based generator, so a run depends on (base_seed, i) only: the
// rows are bit-identical whatever the thread count and order, and any run can be repeated alone from its row.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sowing_robot/core/metrics.h"
#include "sowing_robot/core/reference.h"
#include "sowing_robot/core/runner.h"

namespace sowing_robot {
namespace core {

/// A uniform distribution on [lo, hi] (lo == hi: that value).
struct Uniform {
  double lo = 0.0, hi = 0.0;
  double at(double u01) const { return lo + (hi - lo) * u01; }
};

/// What is drawn per run, and how success is judged. Defaults: around the thesis line scenario.
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
  double cross_track_threshold = 0.05;    ///< success: |e_y| below this after settle_time [m]

  std::string validate() const;
};

/// What run `index` draws (the CSV's drawn columns).
struct RunDraw {
  std::int64_t index = 0;
  double mass_scale = 1.0, inertia_scale = 1.0, amplitude = 0.0, phase = 0.0;
  std::uint64_t noise_seed = 0;
  double start_x = 0.0, start_y = 0.0, start_theta = 0.0;
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
  bool diverged = false;
  bool success = false;
  std::string failure;  ///< why not a success ("" on success): diverged, cross-track
};

/// Runs base (its controller pair, plant, timing) on `reference` for seeds 0..runs-1 with `threads`
/// threads (0: hardware concurrency). progress (optional) is called with the number of finished runs,
/// from whichever thread finished one (serialised). Throws std::invalid_argument for a bad spec or
/// scenario or runs < 1.
std::vector<RunRow> runMonteCarlo(const Scenario& base, const ReferenceSource& reference, const MonteCarloSpec& spec,
                                  std::int64_t runs, int threads = 0,
                                  const std::function<void(std::int64_t)>& progress = {});

/// One metric over the runs. Diverged runs count: their +inf makes mean, std and worst +inf. NaN (a
/// figure a run does not have, e.g. a rise time never reached) is left out; all NaN gives NaN. p95 is
/// the nearest-rank 95th percentile.
struct Statistic {
  double mean = 0.0, std = 0.0, p95 = 0.0, worst = 0.0;
};
Statistic statistic(std::vector<double> values);

/// The names of the per-run metric columns, in CSV order, and their values for a row.
const std::vector<std::string>& metricColumns();
std::vector<double> metricValues(const RunRow& row);

/// Tidy CSV: header line, then one line per row: scenario, controller, seed, the draws, every metric.
std::string runsCsvHeader();
std::string runsCsvLines(const std::string& scenario, const std::string& controller, const std::vector<RunRow>& rows);
/// Markdown section for one scenario and controller: success rate with failure reasons, then per metric
/// mean, std, p95 and worst.
std::string reportSection(const std::string& scenario, const std::string& controller, const std::vector<RunRow>& rows);

}  // namespace core
}  // namespace sowing_robot
