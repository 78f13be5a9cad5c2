// The evaluation protocol (docs/evaluation.md): the `set` key of a scenario file, the content fingerprint that
// judges "seen" by what a scenario holds rather than by its name, and the package's scenarios themselves: each
// states its set, and no test scenario shares its content with a training or validation one.
#include <gtest/gtest.h>

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/scenario_file/scenario_loader.h"
#include "sowing_robot/scenario_file/scenario_sets.h"
#include "sowing_robot/scenario_file/tune_config.h"

#include "../common/test_files.h"

using namespace sowing_robot;
using core::BenchScenario;
using scenario_file::Overlap;
using sowing_robot::test::readFile;
using sowing_robot::test::TempDir;

namespace {
const std::string kSource = SOWING_SOURCE_DIR;
const std::string kSuite = kSource + "/config/scenarios";

/// The suite's file NAME (relative to config/scenarios) with each (from, to) replaced once, renamed to `as`
/// (name and file), written into dir.
std::string edited(const TempDir& dir, const std::string& name, const std::string& as,
                   const std::vector<std::pair<std::string, std::string>>& edits) {
  std::string text = readFile(kSuite + "/" + name + ".yaml");
  const std::string stem = name.substr(name.find_last_of('/') + 1);
  text = std::regex_replace(text, std::regex("\nname: " + stem + "\n"), "\nname: " + as + "\n");
  for (const auto& e : edits) {
    const std::size_t at = text.find(e.first);
    EXPECT_NE(at, std::string::npos) << e.first;
    if (at != std::string::npos) text.replace(at, e.first.size(), e.second);
  }
  return dir.write(as + ".yaml", text);
}

std::string loadError(const std::string& path) {
  try {
    scenario_file::loadScenarioFile(path);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

/// Every *.yaml under dir, at any depth.
void yamlFiles(const std::string& dir, std::vector<std::string>& out) {
  DIR* d = ::opendir(dir.c_str());
  if (!d) return;
  while (const dirent* e = ::readdir(d)) {
    const std::string n = e->d_name;
    if (n == "." || n == "..") continue;
    const std::string p = dir + "/" + n;
    struct stat st;
    if (::stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
      yamlFiles(p, out);
    else if (n.size() > 5 && n.compare(n.size() - 5, 5, ".yaml") == 0)
      out.push_back(p);
  }
  ::closedir(d);
}
}  // namespace

TEST(ScenarioSets, TheSetKeyIsReadAndChecked) {
  TempDir dir;
  // Without the key: validation (a scenario is test only when its file says so).
  std::string text = readFile(kSuite + "/thesis_line.yaml");
  text = std::regex_replace(text, std::regex("\nset: [^\n]*\n"), "\n");
  text = std::regex_replace(text, std::regex("name: thesis_line"), "name: plain");
  EXPECT_EQ(text.find("\nset:"), std::string::npos);
  EXPECT_EQ(scenario_file::loadScenarioFile(dir.write("plain.yaml", text)).set, "validation");
  for (const char* set : {"training", "validation", "test"}) {
    SCOPED_TRACE(set);
    const std::string p = edited(dir, "thesis_line", "named", {{"\nset: validation", std::string("\nset: ") + set}});
    EXPECT_EQ(scenario_file::loadScenarioFile(p).set, set);
  }
  // A bad value: one line naming the file, the value and the allowed ones.
  const std::string bad = edited(dir, "thesis_line", "bad", {{"\nset: validation", "\nset: tset"}});
  const std::string e = loadError(bad);
  EXPECT_NE(e.find(bad), std::string::npos) << e;
  EXPECT_NE(e.find("set 'tset' is none of training, validation, test"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  const std::string list = edited(dir, "thesis_line", "list", {{"\nset: validation", "\nset: [test]"}});
  EXPECT_NE(loadError(list).find("set must be one of training, validation, test"), std::string::npos);
  EXPECT_EQ(scenario_file::checkScenarioSet("test"), "");
  EXPECT_NE(scenario_file::checkScenarioSet("Test"), "");
}

TEST(ScenarioSets, TwoScenariosDifferingOnlyByNameAreSeen) {
  TempDir dir;
  // Another name, description, set and duration: the same content.
  const auto a = scenario_file::loadScenario("wet_line", kSuite);
  const auto b = scenario_file::loadScenarioFile(edited(dir, "wet_line", "renamed",
                                                        {{"\ndescription: ", "\ndescription: another name for "},
                                                         {"\nset: validation", "\nset: test"},
                                                         {"duration: 25.0", "duration: 30.0"}}));
  const auto fa = scenario_file::fingerprintOf(a), fb = scenario_file::fingerprintOf(b);
  EXPECT_EQ(scenario_file::overlapOf(fa, fb), Overlap::same_content);
  EXPECT_EQ(fa.digest(), fb.digest());
  // So a test scenario that is wet_line under another name is caught, and says what it shares with whom.
  const auto overlaps = scenario_file::testOverlaps(b, scenario_file::scenarioCatalog(kSuite));
  std::string all;
  for (const auto& o : overlaps) all += o + "\n";
  EXPECT_NE(all.find("wet_line (validation): same layout, soil and draws (base_seed 1)"), std::string::npos) << all;
  // The same robot with another base seed: the world is still the one seen.
  const auto c =
      scenario_file::loadScenarioFile(edited(dir, "wet_line", "reseeded", {{"base_seed: 1", "base_seed: 9"}}));
  EXPECT_EQ(scenario_file::overlapOf(fa, scenario_file::fingerprintOf(c)), Overlap::same_world);
  // The obstacles' order in a field file is no difference.
  auto d = scenario_file::loadScenario("thesis_field", kSuite);
  auto e = d;
  std::reverse(e.obstacles.begin(), e.obstacles.end());
  EXPECT_EQ(scenario_file::overlapOf(scenario_file::fingerprintOf(d), scenario_file::fingerprintOf(e)),
            Overlap::same_content);
}

TEST(ScenarioSets, ScenariosDifferingInSoilAreNotSeen) {
  TempDir dir;
  const auto a = scenario_file::loadScenario("wet_line", kSuite);
  const auto fa = scenario_file::fingerprintOf(a);
  // Another soil, the same draws: the world differs; what is shared (the draws) is named.
  const auto wetter = scenario_file::fingerprintOf(
      scenario_file::loadScenarioFile(edited(dir, "wet_line", "wetter", {{"mu_peak: 0.3", "mu_peak: 0.25"}})));
  EXPECT_NE(fa.soil, wetter.soil);
  EXPECT_EQ(fa.layout, wetter.layout);
  EXPECT_EQ(scenario_file::overlapOf(fa, wetter), Overlap::same_draws);
  // Another soil and another base seed: held out.
  const auto other = scenario_file::fingerprintOf(scenario_file::loadScenarioFile(
      edited(dir, "wet_line", "other", {{"mu_peak: 0.3", "mu_peak: 0.25"}, {"base_seed: 1", "base_seed: 9"}})));
  EXPECT_EQ(scenario_file::overlapOf(fa, other), Overlap::none);
  // A soil patch moved by a centimetre is another soil too.
  const auto field = scenario_file::loadScenario("wet_soil", kSuite);
  auto moved = field;
  ASSERT_TRUE(moved.realism && !moved.realism->patches.empty());
  moved.realism->patches[0].polygon[0].x() += 0.01;
  EXPECT_NE(scenario_file::fingerprintOf(field).soil, scenario_file::fingerprintOf(moved).soil);
  // The tool's draft is a load, not the soil; the layout's rows are content.
  auto draft = a;
  draft.realism->traction->draft_force = 20.0;
  EXPECT_EQ(scenario_file::overlapOf(fa, scenario_file::fingerprintOf(draft)), Overlap::same_content);
  auto line = a;
  line.line_y = 2.0;
  EXPECT_NE(fa.layout, scenario_file::fingerprintOf(line).layout);
}

// The benchmark's "held out" verdict for robust-tuned gains compares content: train_wet_line is wet_line with
// mu 0.35 instead of 0.3 (held out, other draws); a renamed copy of a training scenario is TRAINED ON.
TEST(ScenarioSets, TheHeldOutVerdictComparesContent) {
  TempDir dir;
  const auto catalog = scenario_file::scenarioCatalog(kSuite);
  const std::vector<scenario_file::TrainingRecord> training{
      {"train_wet_line", 2, 1001}, {"train_wet_rows", 3, 1001}, {"train_dry_line", 2, 1001}};
  const auto verdict = [&](const BenchScenario& b) {
    return scenario_file::heldOutVerdict(training, b, 10, catalog, kSuite);
  };
  EXPECT_EQ(verdict(scenario_file::loadScenario("wet_line", kSuite)),
            "held out (content differs from every training scenario)");
  const auto copy = scenario_file::loadScenarioFile(edited(dir, "training/train_wet_line", "copy", {}));
  EXPECT_EQ(verdict(copy), "TRAINED ON: same content as training scenario train_wet_line; runs 0-1 are training runs");
  auto reseeded = copy;
  reseeded.spec.base_seed = 1;
  EXPECT_EQ(verdict(reseeded), "SEEN IN TRAINING: same layout and soil as train_wet_line (other draws)");
  // The records' base seed is the tuning's, not the file's.
  const std::vector<scenario_file::TrainingRecord> other_seed{{"train_wet_line", 2, 5}};
  EXPECT_EQ(scenario_file::heldOutVerdict(other_seed, copy, 10, catalog, kSuite).rfind("SEEN IN TRAINING", 0), 0u);
  // A training scenario the catalogue lacks cannot be judged, and says so.
  EXPECT_EQ(scenario_file::heldOutVerdict({{"no_such", 1, 1}}, copy, 10, catalog, kSuite).rfind("CANNOT JUDGE", 0), 0u);
}

// A robust tuning may not train on a test scenario.
TEST(ScenarioSets, TheTunerRefusesATestScenario) {
  TempDir dir;
  const std::string config =
      dir.write("tune.yaml",
                "pso_tuner: {particles: 2, iterations: 0, controller: kanayama+atsmc}\nrobust:\n  training:\n"
                "    - {scenario: " +
                    kSuite + "/test/test_polder_clay.yaml, runs: 1, base_seed: 1}\n");
  try {
    scenario_file::loadTuneConfig(config, "", kSource);
    ADD_FAILURE() << "a test scenario was accepted for training";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("a test scenario cannot be trained on"), std::string::npos) << e.what();
  }
}

// Every file under config/scenarios is a field config (reference_generator:) or a scenario that states its set,
// in the directory of that set: training/ holds training scenarios, test/ test scenarios, the rest validation.
TEST(ScenarioSets, EveryPackageScenarioStatesItsSet) {
  std::vector<std::string> files;
  yamlFiles(kSuite, files);
  ASSERT_GT(files.size(), 15u);
  int scenarios = 0;
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    const std::string text = readFile(f);
    if (text.find("\nreference_generator:") != std::string::npos || text.rfind("reference_generator:", 0) == 0)
      continue;
    ++scenarios;
    EXPECT_TRUE(std::regex_search(text, std::regex("\nset: (training|validation|test)\\b"))) << "no set: line";
    const BenchScenario b = scenario_file::loadScenarioFile(f);
    const std::string rel = f.substr(kSuite.size() + 1);
    const std::string expected = rel.rfind("training/", 0) == 0 ? "training"
                                 : rel.rfind("test/", 0) == 0   ? "test"
                                                                : "validation";
    EXPECT_EQ(b.set, expected);
  }
  EXPECT_EQ(static_cast<std::size_t>(scenarios), scenario_file::scenarioCatalog(kSuite).size());
}

// The test set: at least three wet fields and a dry one, each differing from every training and validation
// scenario in layout, in soil and in its base seed (stricter than the benchmark's refusal, which asks for another
// world or other draws).
TEST(ScenarioSets, NoTestScenarioSharesContentWithATrainingOrValidationOne) {
  const auto catalog = scenario_file::scenarioCatalog(kSuite);
  int tests = 0, wet = 0, dry = 0;
  for (const auto& t : catalog) {
    if (t.scenario.set != "test") continue;
    SCOPED_TRACE(t.path);
    ++tests;
    EXPECT_TRUE(scenario_file::testOverlaps(t.scenario, catalog).empty());
    ASSERT_TRUE(t.scenario.realism && t.scenario.realism->traction);
    bool has_wet = t.scenario.realism->traction->mu_peak < 0.45;
    for (const auto& p : t.scenario.realism->patches) has_wet = has_wet || p.mu_peak < 0.45;
    (has_wet ? wet : dry) += 1;
    for (const auto& s : catalog) {
      if (s.scenario.set == "test") continue;
      SCOPED_TRACE(s.scenario.name);
      EXPECT_EQ(scenario_file::overlapOf(t.fingerprint, s.fingerprint), Overlap::none);
      EXPECT_NE(t.fingerprint.layout, s.fingerprint.layout);
      EXPECT_NE(t.fingerprint.soil, s.fingerprint.soil);
      EXPECT_NE(t.scenario.spec.base_seed, s.scenario.spec.base_seed);
    }
  }
  EXPECT_GE(wet, 3);
  EXPECT_GE(dry, 1);
  EXPECT_EQ(tests, wet + dry);
}

// No test soil is unsowable by design: the field check (checkFieldDraft, in the benchmark's report header) finds
// that each soil of each test field, wet patches included, carries the drill at the agronomic band's shallowest
// depth and the nominal mass. A test field is read, never run, to check this.
TEST(ScenarioSets, EveryTestSoilCarriesTheDrillAtItsShallowestDepth) {
  int tests = 0;
  for (const auto& t : scenario_file::scenarioCatalog(kSuite)) {
    if (t.scenario.set != "test") continue;
    SCOPED_TRACE(t.path);
    ++tests;
    ASSERT_TRUE(t.scenario.realism && t.scenario.realism->traction);
    const core::LoopConfig& c = *t.scenario.realism;
    const auto checks = core::checkFieldDraft(t.scenario.base.robot, 1.0, *c.traction, c.patches, c.seeding.depth_min);
    EXPECT_EQ(checks.size(), c.patches.size() + 1);  // the field's soil, then each patch
    EXPECT_EQ(core::fieldDraftWarnings(checks), "");
  }
  EXPECT_GE(tests, 4);
}
