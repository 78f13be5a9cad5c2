// The command-line tuner's configuration (`tune --config FILE`, no ROS master): one YAML file with
// the pso_tuner block of config/pso.yaml (same keys, same table, same checks; its gains list too) and an
// optional scenario block for the base scenario that tune.launch reads from the nodes' config files.
//
//   pso_tuner: {particles: 20, iterations: 30, seed: 1, controller: kanayama+atsmc, duration: 25.0, ...,
//               gains: [{name: kx, lower: 0.1, upper: 10.0}, ...]}
//   scenario:
//     start: {x: -1.0, y: 0.0, theta: 0.0}            # [m, m, rad]
//     line: {x0: 0.0, v_r: 1.0, y: 3.0}               # x_d = x0 + v_r t, y_d = y
//     plant: {disturbance: {...}, noise: {...}, mismatch: {...}}   # plant_sim's keys (disturbanceTable)
//     controllers: {kinematic_controller: {...}, torque_controller: {...}}   # gains not tuned
//   robust:                                           # optional: robust tuning (robust_tuning.h)
//     aggregate: mean                                 # mean | quantile
//     quantile: 0.9                                   # for quantile, in (0, 1]
//     failure_penalty: 1.0                            # per failed run, and the tracking term's cap [m]
//     max_slip_share: 1.0                             # a run longer beyond 2x the peak's slip fails (1: off)
//     profile: field                                  # applied on every training scenario: a name in
//                                                     # config/profiles, or a file relative to this file
//     training:                                       # benchmark scenario files, relative to this file
//       - {scenario: ../scenarios/training/wet_turns.yaml, runs: 4, base_seed: 1001}
// With robust:, each evaluation is the mean (or quantile) over the training runs, each scenario with its own
// duration, rate, start, plant and draws; pso_tuner's duration and control_rate and scenario/start, line,
// plant are then not used (refused), scenario/controllers still sets the gains not tuned.
//
// Absent scenario keys keep the core's defaults (Scenario, LineReference). Errors: std::invalid_argument
// with one line "FILE: what is wrong" (unknown key, wrong type, out of range, bad gain bounds).
#pragma once

#include <string>
#include <vector>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/evaluation/pso.h"
#include "sowing_robot/core/evaluation/robust_tuning.h"
#include "sowing_robot/core/evaluation/tuning.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {
namespace scenario_file {

struct TuneConfig {
  core::Scenario base;
  double line_x0 = 0.0, line_v_r = 1.0, line_y = 3.0;
  std::vector<core::GainBounds> gains;  ///< the pso_tuner/gains list, or every tunable gain of the pair
  core::TuningObjective objective;
  core::PsoParams pso;  ///< lower/upper filled from gains
  std::string output;   ///< pso_tuner/output ("" if not given)
  std::string text;     ///< the file's bytes (part of the checkpoint fingerprint)
  /// robust: given: the training set (each scenario with the pair and gains of `base`) and its objective.
  std::vector<core::TrainingScenario> training;
  core::RobustObjective robust;
  bool isRobust() const { return !training.empty(); }

  core::LineReference reference() const { return core::LineReference(line_v_r, line_y, line_x0); }
  /// One line: duration, rate, pair, start, line, disturbance, mismatch, noise.
  std::string scenarioText() const;
};

/// `controller` (not ""): replaces pso_tuner/controller (tune --controller), before the gains are chosen.
/// `source_dir`: the package's source tree, where a profile name in robust/profile is looked up
/// (resolveProfile).
TuneConfig loadTuneConfig(const std::string& path, const std::string& controller, const std::string& source_dir);

}  // namespace scenario_file
}  // namespace sowing_robot
