// The evaluation protocol's side of the scenario files (docs/evaluation.md): which set a scenario belongs to
// (training: the tuner sees it; validation: design choices are made on it; test: reported, never looked at while
// designing), and whether two scenarios hold the same content whatever their names. A scenario's content is its
// world (the track's geometry, the obstacles and the start: its layout; the ground's coefficients and the soil
// patches: its soil) and its draws (base seed and the ranges drawn from); the fingerprint is that content written
// out canonically (every number to 17 digits), so equal text means equal content.
//
// Errors: std::invalid_argument with one line (a scenario file that does not load, an unknown set name).
#pragma once

#include <string>
#include <vector>

#include "sowing_robot/core/evaluation/benchmark.h"
#include "sowing_robot/scenario_file/scenario_loader.h"

namespace sowing_robot {
namespace scenario_file {

/// The set names, in the protocol's order.
const std::vector<std::string>& scenarioSets();
/// "" when `set` is one of scenarioSets(), else the one-line reason (naming the allowed values).
std::string checkScenarioSet(const std::string& set);

/// A scenario's content, canonically written: three parts compared one by one.
struct ScenarioFingerprint {
  std::string layout;  ///< track kind, its geometry (line, sine or the field's rows), obstacles, start pose
  std::string soil;    ///< traction on or off, the ground's mu_peak, mu_slide, rolling resistance, the patches
  std::string draws;   ///< base seed and every range drawn from (mass, inertia, disturbance, noise, start)
  /// A short hex digest of the three parts (FNV-1a 64), for a report line; equal content gives an equal digest.
  std::string digest() const;
};
/// The content of `b` (its name, description, set, duration, controllers, sensors and estimator are not content:
/// two scenarios differing only there have the same fingerprint). Read the scenario without a profile: a
/// profile is part of the system under test, not of the scenario.
ScenarioFingerprint fingerprintOf(const core::BenchScenario& b);

/// How one scenario's content relates to another's.
enum class Overlap {
  none,          ///< other world and other draws
  same_draws,    ///< other world, the same draws (base seed and ranges): the same random numbers
  same_world,    ///< the same layout and soil, other draws
  same_content,  ///< the same world and draws: runs 0..N-1 are the same runs
};
Overlap overlapOf(const ScenarioFingerprint& a, const ScenarioFingerprint& b);
/// "same layout and soil", "same draws (base seed S and ranges)", ... ("" for none).
std::string describeOverlap(Overlap o, const ScenarioFingerprint& a);

/// A scenario of the package's catalogue: its file, what it holds, and its fingerprint.
struct CatalogEntry {
  std::string path;
  core::BenchScenario scenario;  ///< read without a profile
  ScenarioFingerprint fingerprint;
};
/// Every scenario file under `dir` (config/scenarios: its *.yaml and those of its sub-directories, one level
/// down, e.g. training/, test/, path_follower/), each read without a profile; files that are field configs
/// (a top-level reference_generator:, such as training/field_train_wet_rows.yaml) are skipped, as are
/// sub-directories' own sub-directories (test/fields/). Throws what loadScenarioFile throws for a bad file.
std::vector<CatalogEntry> scenarioCatalog(const std::string& dir);

/// What the protocol says of one scenario about to be run against the catalogue: for a test scenario, every
/// training or validation scenario whose content overlaps it (each a line "NAME (SET): what is shared").
/// Empty: nothing overlaps (or the scenario is not a test scenario). `b` is read without a profile, with the
/// run's base seed (benchmark --base-seed) in place. Test scenarios are not compared with each other.
std::vector<std::string> testOverlaps(const core::BenchScenario& b, const std::vector<CatalogEntry>& catalog);

/// What the benchmark's report says of a scenario run with gains trained on `training` (the gains file's
/// records, trainingOf), judged by content: each record's scenario is looked up by name in the catalogue (its
/// draws with the record's base seed) and compared with `b` (read without a profile, the run's base seed in
/// place). "TRAINED ON: same content as training scenario X; runs 0-K are training runs", "SEEN IN TRAINING:
/// same layout and soil as X (other draws)", "SEEN IN TRAINING: same draws as X (...)", "held out (content
/// differs from every training scenario)"; a record whose scenario is not in the catalogue makes the verdict
/// "CANNOT JUDGE: training scenario X is not in DIR".
std::string heldOutVerdict(const std::vector<TrainingRecord>& training, const core::BenchScenario& b, long long runs,
                           const std::vector<CatalogEntry>& catalog, const std::string& catalog_dir);

}  // namespace scenario_file
}  // namespace sowing_robot
