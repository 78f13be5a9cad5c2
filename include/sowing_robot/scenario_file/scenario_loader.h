// The benchmark's YAML side: config/scenarios/NAME.yaml -> core::BenchScenario, and the tuned
// gains of a controller pair (config/tuned/OUTER+INNER.yaml) onto a core::Scenario. Kept out of the
// ROS-free core because it needs yaml-cpp; every value goes through the core's parameter tables (type and
// range checks, unknown keys refused), and all physics stays in the core (benchmark.h runs the scenario).
//
// Errors: std::invalid_argument with one line "FILE: what is wrong" (an unknown key, a missing one, a
// value of the wrong type or out of range, an unknown scenario name).
#pragma once

#include <string>
#include <vector>

#include "sowing_robot/core/evaluation/benchmark.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {
namespace scenario_file {

/// The scenario file at `path` (its `name` must equal the file's stem; its `set`, training | validation | test,
/// defaults to validation: BenchScenario::set, docs/evaluation.md). A field scenario's `field/config`
/// is read relative to the scenario file's directory (with its plant_sim/field/patches, used with traction on).
/// Blocks traction:, sensors: (sensors/seed refused: drawn per run), estimator: and feedback: set
/// BenchScenario::realism (docs/benchmark.md).
/// `profile` (a file path, "" for none): a set-up applied on top of the scenario's own blocks
/// (config/profiles/field.yaml: the recommended drive train). A profile is a rosparam file (sim.launch
/// profile:= loads it as it stands): its node blocks plant_sim/{traction, motor, sensors},
/// torque_controller/traction_control, reference_generator/speed_governor and state_estimator/estimator are
/// merged key by key into the scenario's blocks of those names (the profile's value wins), its
/// profile/feedback replaces the scenario's feedback:; profile/{name, description} are its own.
core::BenchScenario loadScenarioFile(const std::string& path, const std::string& profile = "");

/// The same profile applied onto an in-process loop's configuration (the Python module's run_estimated(profile=)):
/// each block key by key through its table over what `cfg` holds (plant_sim/traction/enabled true puts the
/// traction plant in, with cfg's traction parameters if it had them), profile/feedback over cfg.feedback.
/// Throws std::invalid_argument "FILE: what is wrong".
void applyProfileTo(const std::string& profile, core::LoopConfig& cfg);

/// A profile's file and the directory of the gains tuned for it.
struct ProfileFiles {
  std::string file;       ///< the profile (a rosparam file: loadScenarioFile's, applyProfileTo's `profile`)
  std::string gains_dir;  ///< its OUTER+INNER.yaml gains (tunedGainsFile's DIR); "" when it has none
};

/// The one reading of a profile argument (benchmark --profile, tune's robust/profile, run_estimated(profile=)),
/// as sim.launch profile:=NAME reads it. `name_or_path` is a file path when it contains '/' or ends with .yaml:
/// taken as it is, no gains directory. Else a name: SOURCE/config/profiles/NAME.yaml, its gains
/// SOURCE/config/tuned/NAME/ when that directory exists (else "": the gains as without a profile). An unknown
/// name: std::invalid_argument "unknown profile 'NAME' (available in SOURCE/config/profiles: field)".
ProfileFiles resolveProfile(const std::string& name_or_path, const std::string& source_dir);

/// `name_or_path`: a file path (contains '/' or ends with .yaml) or a scenario name looked up as
/// DIR/NAME.yaml; an unknown name lists the known ones.
core::BenchScenario loadScenario(const std::string& name_or_path, const std::string& dir,
                                 const std::string& profile = "");

/// The scenario names in `dir` (every *.yaml, sorted).
std::vector<std::string> scenarioNames(const std::string& dir);

/// Models a scenario may require (`requires:`) that are announced but not built yet: empty since
/// "wet_soil" and "estimated_pose" landed (core::availableModels(); their blocks traction:, sensors:,
/// estimator:, feedback: are read in loadScenarioFile through the nodes' tables). Extension point: a model
/// announced before it is built goes here, and a scenario requiring it is refused with "not available yet".
const std::vector<std::string>& pendingModels();

/// Applies a tuned-gains file (results/tuned_gains.yaml's format: groups kinematic_controller (Kanayama),
/// torque_controller (sliding mode; its `mode`, if given, must be the pair's), pure_pursuit, pid; each
/// read through its parameter table) onto sc. Unknown groups or keys are refused.
void applyTunedGains(const std::string& path, core::Scenario& sc);

/// DIR/OUTER+INNER.yaml for the pair of sc if that file exists, else "".
std::string tunedGainsFile(const std::string& dir, const core::Scenario& sc);

/// One scenario a robust tuning trained on: runs 0..runs-1 of base seed base_seed.
struct TrainingRecord {
  std::string scenario;
  long long runs = 0;
  unsigned long long base_seed = 0;
};
/// The training set a gains file records (its "# training: NAME runs N base_seed S" header lines, written by
/// tune with a robust: block); empty for gains tuned on one run (or a file that cannot be read).
std::vector<TrainingRecord> trainingOf(const std::string& gains_path);
/// What the benchmark's report says of a scenario and such a training set: scenario_sets.h's heldOutVerdict,
/// which compares content, not names.

}  // namespace scenario_file
}  // namespace sowing_robot
