// The runs core_bench and alloc_check measure, all through the product's entry point (runClosedLoop,
// with a LoopConfig or without; the one loop of closed_loop.h):
//   the thesis scenario (as pso_tuning_bench): 25 s at 1 kHz, start (-1, 0, 0), line x = t, y = 3 at 1 m/s,
//   sinusoidal wheel disturbance (A 2.75 N·m, w 3 rad/s), plant 20 % heavier than the controllers' model;
//   optionally the potential field with the thesis's three obstacles (20, 3), (50, 3), (80, 3), radius 0.3 m
//   (config/field_thesis.yaml);
//   the field profile: config/profiles/field.yaml read by the benchmark's own reader (scenario_file::applyProfileTo, as
//   `benchmark --profile` and sowing_robot.core.run_estimated(profile=) read it), with the gains tuned for it
//   (config/tuned/field/PAIR.yaml, as sim.launch profile:=field loads them), so the figures follow the profile.
#pragma once

#include <string>
#include <vector>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/planning/potential_field.h"
#include "sowing_robot/core/simulation/runner.h"
#include "sowing_robot/scenario_file/scenario_loader.h"

#ifndef SOWING_SOURCE_DIR
#error "SOWING_SOURCE_DIR (the source tree, for config/) must be defined by the build"
#endif

namespace sowing_robot {
namespace bench {

inline core::Scenario thesisScenario() {
  core::Scenario sc;
  sc.disturbance.sinusoidal = true;
  sc.disturbance.mass_scale = sc.disturbance.inertia_scale = 1.2;
  return sc;
}

inline core::LineReference thesisLine() { return core::LineReference(1.0, 3.0, 0.0); }

inline core::PotentialField thesisPotentialField() {
  core::RowLine row;  // x0 = 0, y0 = 3, heading 0, speed 1 m/s
  return core::PotentialField(core::PotentialFieldParams{}, row,
                              std::vector<core::Obstacle>{{20.0, 3.0, 0.3}, {50.0, 3.0, 0.3}, {80.0, 3.0, 0.3}});
}

inline std::string sourcePath(const std::string& relative) { return std::string(SOWING_SOURCE_DIR) + "/" + relative; }

/// The field profile's loop configuration (config/profiles/field.yaml as it stands: traction plant, motors,
/// command limits, traction control, speed governor, hitch control, fused feedback with the slip-aware EKF).
/// Throws std::invalid_argument when the file does not read.
inline core::LoopConfig fieldProfileConfig() {
  core::LoopConfig cfg;
  scenario_file::applyProfileTo(sourcePath("config/profiles/field.yaml"), cfg);
  const std::string e = cfg.validate();
  if (!e.empty()) throw std::invalid_argument("config/profiles/field.yaml: " + e);
  return cfg;
}

/// The thesis scenario with the gains the field profile is used with (config/tuned/field/kanayama+atsmc.yaml).
inline core::Scenario fieldProfileScenario() {
  core::Scenario sc = thesisScenario();
  const std::string gains = scenario_file::tunedGainsFile(sourcePath("config/tuned/field"), sc);
  if (gains.empty()) throw std::invalid_argument("no config/tuned/field/" + sc.controllerName() + ".yaml");
  scenario_file::applyTunedGains(gains, sc);
  return sc;
}

}  // namespace bench
}  // namespace sowing_robot
