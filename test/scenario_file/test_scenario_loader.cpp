// The benchmark's scenario files and tuned gains (scenario_file/scenario_loader.h): every suite file loads, a typo or
// a missing key is refused naming it, tuned gains go through the parameter tables, and a field scenario's
// success counts the body's contacts with the obstacles (core::runBenchmark).
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <stdexcept>
#include <string>

#include "sowing_robot/core/evaluation/bench_row.h"
#include "sowing_robot/scenario_file/scenario_loader.h"
#include "sowing_robot/scenario_file/tune_config.h"

using namespace sowing_robot;
using core::BenchScenario;
using core::TrackKind;

#include "../common/test_files.h"

using sowing_robot::test::readFile;
using sowing_robot::test::TempDir;

namespace {
const std::string kSource = SOWING_SOURCE_DIR;
const std::string kSuite = kSource + "/config/scenarios";

/// thesis_line.yaml with `from` replaced by `to` (once), written as DIR/thesis_line.yaml.
std::string variant(const TempDir& dir, const std::string& from, const std::string& to) {
  std::string text = readFile(kSuite + "/thesis_line.yaml");
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return dir.write("thesis_line.yaml", text);
}

std::string loadError(const std::string& path) {
  try {
    scenario_file::loadScenarioFile(path);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(ScenarioLoader, EverySuiteFileLoads) {
  const auto names = scenario_file::scenarioNames(kSuite);
  for (const char* expected : {"thesis_line", "thesis_field", "three_row_field", "sine_rows", "heavy_robot",
                               "disturbance_sweep", "wet_soil", "estimated_pose"})
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  for (const auto& n : names) {
    SCOPED_TRACE(n);
    BenchScenario b;
    ASSERT_NO_THROW(b = scenario_file::loadScenario(n, kSuite));
    EXPECT_EQ(b.name, n);
    EXPECT_EQ(b.validate(), "");
  }
  // What the files say arrives where it belongs.
  const BenchScenario line = scenario_file::loadScenario("thesis_line", kSuite);
  EXPECT_EQ(line.track, TrackKind::line);
  EXPECT_EQ(line.base.duration, 25.0);
  EXPECT_EQ(line.base.control_period_ns, 1000000);
  EXPECT_EQ(line.spec.mass_scale.lo, 0.8);
  EXPECT_EQ(line.spec.mass_scale.hi, 1.5);
  EXPECT_EQ(line.spec.cross_track_threshold, 0.05);
  const BenchScenario field = scenario_file::loadScenario("thesis_field", kSuite);
  EXPECT_EQ(field.track, TrackKind::field);
  ASSERT_EQ(field.obstacles.size(), 3u);
  EXPECT_EQ(field.obstacles[1].x, 50.0);
  EXPECT_EQ(field.field.row_length, 100.0);
  EXPECT_EQ(field.field.potential.beta, 4.0);
  const BenchScenario rows = scenario_file::loadScenario("three_row_field", kSuite);
  EXPECT_EQ(rows.field.rows, 3);
  EXPECT_EQ(rows.obstacles.size(), 1u);
  EXPECT_EQ(scenario_file::loadScenario("sine_rows", kSuite).track, TrackKind::sine);
  EXPECT_GE(scenario_file::loadScenario("heavy_robot", kSuite).spec.mass_scale.lo, 1.3);
  EXPECT_GE(scenario_file::loadScenario("disturbance_sweep", kSuite).spec.amplitude.hi, 5.0);
  // The same fields through the path follower (config/scenarios/path_follower/): only the follower differs.
  for (const char* n : {"thesis_field", "three_row_field"}) {
    SCOPED_TRACE(n);
    const BenchScenario own = scenario_file::loadScenario(n, kSuite);
    const BenchScenario path =
        scenario_file::loadScenarioFile(kSuite + "/path_follower/" + std::string(n) + "_path.yaml");
    EXPECT_EQ(own.field.follower, core::FieldFollower::kPotential);
    EXPECT_EQ(path.field.follower, core::FieldFollower::kPath);
    EXPECT_EQ(path.field.rows, own.field.rows);
    EXPECT_EQ(path.obstacles.size(), own.obstacles.size());
    EXPECT_EQ(path.base.duration, own.base.duration);
    EXPECT_EQ(path.spec.base_seed, own.spec.base_seed);
  }
}

TEST(ScenarioLoader, TyposAndMissingKeysAreRefusedNamingThem) {
  TempDir dir;
  // The unmodified copy loads (so each failure below is the edit's).
  EXPECT_EQ(loadError(variant(dir, "name: thesis_line", "name: thesis_line")), "");
  std::string e = loadError(variant(dir, "  mass_scale:", "  mass_scal:"));
  EXPECT_NE(e.find("unknown key 'draws/mass_scal'"), std::string::npos) << e;
  e = loadError(variant(dir, "duration: 25.0", "duraton: 25.0"));
  EXPECT_NE(e.find("duraton"), std::string::npos) << e;
  e = loadError(variant(dir, "  cross_track_threshold: 0.05", "  cross_track_threshold: 0.05x"));
  EXPECT_NE(e.find("cross_track_threshold"), std::string::npos) << e;
  e = loadError(variant(dir, "  cross_track_threshold: 0.05", "  cross_track_threshold: 0.05\n  rule: seeded"));
  EXPECT_NE(e.find("success/rule must be tracking or sown"), std::string::npos) << e;
  e = loadError(variant(dir, "  cross_track_threshold: 0.05", "  cross_track_threshold: 0.05\n  min_sown_share: 1.5"));
  EXPECT_NE(e.find("min_sown_share must be in [0, 1]"), std::string::npos) << e;
  e = loadError(
      variant(dir, "  cross_track_threshold: 0.05", "  cross_track_threshold: 0.05\n  min_quality_of_feed: -1"));
  EXPECT_NE(e.find("min_quality_of_feed"), std::string::npos) << e;
  e = loadError(variant(dir, "  settle_time: 15.0", "  # settle_time gone"));
  EXPECT_NE(e.find("missing key 'success/settle_time'"), std::string::npos) << e;
  e = loadError(variant(dir, "track: line", "track: lnie"));
  EXPECT_NE(e.find("lnie"), std::string::npos) << e;
  e = loadError(variant(dir, "mass_scale: [0.8, 1.5]", "mass_scale: [1.5, 0.8]"));
  EXPECT_NE(e.find("mass_scale"), std::string::npos) << e;
  e = loadError(variant(dir, "disturbance: {frequency: 3.0}", "disturbance: {frequence: 3.0}"));
  EXPECT_NE(e.find("frequence"), std::string::npos) << e;
  {  // a field's follower must be one of the two
    const std::string field = readFile(kSuite + "/path_follower/three_row_field_path.yaml");
    std::string text = field;
    text.replace(text.find("follower: path"), 14, "follower: pth");
    text.replace(text.find("../../field.yaml"), 16, kSuite + "/../field.yaml");
    e = loadError(dir.write("three_row_field_path.yaml", text));
    EXPECT_NE(e.find("field/follower = 'pth' must be one of potential, path"), std::string::npos) << e;
  }
  e = loadError(variant(dir, "name: thesis_line", "name: other"));
  EXPECT_NE(e.find("must be the file's name"), std::string::npos) << e;
  // Every message is one line, starting with the file.
  EXPECT_EQ(e.find('\n'), std::string::npos);
  EXPECT_EQ(e.rfind(dir.path, 0), 0u) << e;
  // An unknown name lists the known ones.
  try {
    scenario_file::loadScenario("thesis_lien", kSuite);
    FAIL();
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("unknown scenario 'thesis_lien'"), std::string::npos) << ex.what();
    EXPECT_NE(std::string(ex.what()).find("thesis_line"), std::string::npos) << ex.what();
  }
}

TEST(ScenarioLoader, RequiredModelsMustBeKnownAndSwitchedOn) {
  // wet_soil and estimated_pose are built (nothing is pending now); a scenario that requires one must switch it on.
  EXPECT_TRUE(scenario_file::pendingModels().empty());
  TempDir dir;
  std::string e = loadError(variant(dir, "requires: []", "requires: [wet_soil]"));
  EXPECT_NE(e.find("requires wet_soil but its traction is not enabled"), std::string::npos) << e;
  e = loadError(variant(dir, "requires: []", "requires: [estimated_pose]"));
  EXPECT_NE(e.find("requires estimated_pose but its feedback is ground_truth"), std::string::npos) << e;
  e = loadError(variant(dir, "requires: []", "requires: [estimated_pose]\nfeedback: fused"));
  EXPECT_EQ(e, "");
  e = loadError(variant(dir, "requires: []", "requires: [dry_soil]"));
  EXPECT_NE(e.find("unknown model 'dry_soil' (available: wet_soil, estimated_pose)"), std::string::npos) << e;
}

TEST(ScenarioLoader, TheNewScenariosCarryTheirPlantSensorsAndFeedback) {
  const BenchScenario wet = scenario_file::loadScenario("wet_soil", kSuite);
  ASSERT_TRUE(wet.realism.has_value());
  ASSERT_TRUE(wet.realism->traction.has_value());
  EXPECT_EQ(wet.realism->traction->draft_force, 10.0);
  EXPECT_EQ(wet.realism->traction->mu_peak, 0.6);  // config/traction.yaml's default
  ASSERT_EQ(wet.realism->patches.size(), 1u);      // config/field_thesis_wet.yaml's patch
  EXPECT_EQ(wet.realism->patches[0].mu_peak, 0.2);
  EXPECT_EQ(wet.realism->patches[0].mu_slide, 0.15);
  EXPECT_EQ(wet.realism->patches[0].rolling_resistance, 0.08);
  EXPECT_EQ(wet.realism->feedback, core::Feedback::ground_truth);
  EXPECT_EQ(wet.obstacles.size(), 3u);
  const BenchScenario est = scenario_file::loadScenario("estimated_pose", kSuite);
  ASSERT_TRUE(est.realism.has_value());
  EXPECT_FALSE(est.realism->traction.has_value());
  EXPECT_EQ(est.realism->feedback, core::Feedback::fused);
  EXPECT_EQ(est.realism->sensors.fix.sigma, 0.02);
  EXPECT_EQ(est.realism->sensors.encoder.ticks_per_turn, 2048);
  // Today's scenarios stay on today's loop.
  EXPECT_FALSE(scenario_file::loadScenario("thesis_line", kSuite).realism.has_value());
  EXPECT_FALSE(scenario_file::loadScenario("thesis_field", kSuite).realism.has_value());
}

namespace {
/// estimated_pose.yaml with `from` replaced by `to` (once), written as DIR/estimated_pose.yaml.
std::string estimatedVariant(const TempDir& dir, const std::string& from, const std::string& to) {
  std::string text = readFile(kSuite + "/estimated_pose.yaml");
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return dir.write("estimated_pose.yaml", text);
}
}  // namespace

TEST(ScenarioLoader, BadTractionSensorAndEstimatorKeysAreRefusedNamingTheKey) {
  TempDir dir;
  const auto oneLine = [&](const std::string& e) {
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_EQ(e.rfind(dir.path, 0), 0u) << e;
  };
  EXPECT_EQ(loadError(estimatedVariant(dir, "sensors: {}", "sensors: {}")), "");
  std::string e = loadError(estimatedVariant(dir, "sensors: {}", "sensors: {fix: {sigmaa: 0.02}}"));
  EXPECT_NE(e.find("unknown key 'sensors/fix/sigmaa'"), std::string::npos) << e;
  oneLine(e);
  e = loadError(estimatedVariant(dir, "sensors: {}", "sensors: {fix: {sigma: -0.02}}"));
  EXPECT_NE(e.find("sensors/fix/sigma"), std::string::npos) << e;
  oneLine(e);
  e = loadError(estimatedVariant(dir, "sensors: {}", "sensors: {seed: 3}"));
  EXPECT_NE(e.find("sensors/seed is drawn per run"), std::string::npos) << e;
  e = loadError(estimatedVariant(dir, "estimator: {}", "estimator: {fix: {delay: -1}}"));
  EXPECT_NE(e.find("estimator/fix/delay"), std::string::npos) << e;
  oneLine(e);
  e = loadError(estimatedVariant(dir, "estimator: {}", "estimator: {bias: {estimat: true}}"));
  EXPECT_NE(e.find("unknown key 'estimator/bias/estimat'"), std::string::npos) << e;
  e = loadError(estimatedVariant(dir, "feedback: fused", "feedback: fusde"));
  EXPECT_NE(e.find("feedback 'fusde' is none of ground_truth, odometry, fused"), std::string::npos) << e;
  oneLine(e);
  e = loadError(estimatedVariant(dir, "sensors: {}", "sensors: {}\ntraction: {enabled: true, mu_peak: nan}"));
  EXPECT_NE(e.find("traction/mu_peak"), std::string::npos) << e;
  oneLine(e);
  e = loadError(estimatedVariant(dir, "sensors: {}", "sensors: {}\ntraction: {enabled: true, mu_slide: 0.9}"));
  EXPECT_NE(e.find("traction/mu_slide"), std::string::npos) << e;
  e = loadError(estimatedVariant(dir, "sensors: {}", "sensors: {}\ntraction: {enabeld: true}"));
  EXPECT_NE(e.find("unknown key 'traction/enabeld'"), std::string::npos) << e;
  // A bad soil patch in the field file: named with its index, as plant_sim names it.
  const std::string wet = readFile(kSource + "/config/field_thesis_wet.yaml");
  std::string bad = std::regex_replace(wet, std::regex("mu_peak: 0.2, mu_slide: 0.15"), "mu_peak: 0.2, mu_slide: 0.3");
  dir.write("field_thesis_wet.yaml", bad);
  std::string scen = readFile(kSuite + "/wet_soil.yaml");
  scen = std::regex_replace(scen, std::regex("\\.\\./field_thesis_wet\\.yaml"), "field_thesis_wet.yaml");
  e = loadError(dir.write("wet_soil.yaml", scen));
  EXPECT_NE(e.find("field/patches[0]"), std::string::npos) << e;
  oneLine(e);
  bad = std::regex_replace(wet, std::regex("rolling_resistance: 0.08"), "rolling_resistence: 0.08");
  dir.write("field_thesis_wet.yaml", bad);
  e = loadError(dir.path + "/wet_soil.yaml");
  EXPECT_NE(e.find("unknown key 'field/patches[0]/rolling_resistence'"), std::string::npos) << e;
  // The drill's draft factor on a patch (SoilPatch::draft_factor): read when given, 1 when not, >= 0.
  bad = std::regex_replace(wet, std::regex("rolling_resistance: 0.08"), "rolling_resistance: 0.08, draft_factor: 1.2");
  dir.write("field_thesis_wet.yaml", bad);
  ASSERT_EQ(loadError(dir.path + "/wet_soil.yaml"), "");
  EXPECT_EQ(scenario_file::loadScenario("wet_soil", dir.path).realism->patches[0].draft_factor, 1.2);
  EXPECT_EQ(scenario_file::loadScenario("wet_soil", kSuite).realism->patches[0].draft_factor, 1.0);
  bad = std::regex_replace(wet, std::regex("rolling_resistance: 0.08"), "rolling_resistance: 0.08, draft_factor: -1");
  dir.write("field_thesis_wet.yaml", bad);
  e = loadError(dir.path + "/wet_soil.yaml");
  EXPECT_NE(e.find("field/patches[0]/draft_factor"), std::string::npos) << e;
  dir.write("field_thesis_wet.yaml", wet);  // the unmodified copy loads: each failure above was the edit's
  EXPECT_EQ(loadError(dir.path + "/wet_soil.yaml"), "");
}

TEST(ScenarioLoader, TunedGainsGoThroughTheParameterTables) {
  TempDir dir;
  core::Scenario sc;
  ASSERT_EQ(core::parseControllerPair("kanayama+atsmc", sc.outer, sc.inner, sc.sliding.adaptive), "");
  EXPECT_EQ(scenario_file::tunedGainsFile(dir.path, sc), "");
  const std::string path = dir.write("kanayama+atsmc.yaml",
                                     "kinematic_controller:\n  kx: 9.5\n  ky: 7.5\n  ktheta: 7.0\n"
                                     "torque_controller:\n  k1: 400.0\n  rate_m: 0.5\n  mode: atsmc\n");
  EXPECT_EQ(scenario_file::tunedGainsFile(dir.path, sc), path);
  scenario_file::applyTunedGains(path, sc);
  EXPECT_EQ(sc.kanayama.kx, 9.5);
  EXPECT_EQ(sc.sliding.k1, 400.0);
  EXPECT_EQ(sc.sliding.rate_m, 0.5);
  // The results/ file of today loads as it is.
  core::Scenario today = core::Scenario();
  EXPECT_NO_THROW(scenario_file::applyTunedGains(kSource + "/results/tuned_gains.yaml", today));
  EXPECT_NE(today.kanayama.kx, core::Scenario().kanayama.kx);
  // Unknown keys and groups, values out of range, a file of the other mode: refused.
  auto refused = [&](const std::string& text, const std::string& needle) {
    core::Scenario s = core::Scenario();
    const std::string p = dir.write("bad.yaml", text);
    try {
      scenario_file::applyTunedGains(p, s);
      ADD_FAILURE() << text;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  refused("kinematic_controller:\n  kxx: 1.0\n", "kxx");
  refused("torque_controler:\n  k1: 1.0\n", "torque_controler");
  refused("kinematic_controller:\n  kx: -1.0\n", "kx");
  refused("torque_controller:\n  mode: tsmc\n", "mode");
  refused("torque_controller:\n  kp: fast\n", "kp");
  refused("pid:\n  kp: 3.0\n", "pid");  // the nodes' groups only: the PID's keys sit under torque_controller
  core::Scenario pid;
  ASSERT_EQ(core::parseControllerPair("rpp+pid", pid.outer, pid.inner, pid.sliding.adaptive), "");
  scenario_file::applyTunedGains(
      dir.write("rpp+pid.yaml", "kinematic_controller:\n  lookahead_dist: 0.8\ntorque_controller:\n  kp: 3.0\n"), pid);
  EXPECT_EQ(pid.pure_pursuit.lookahead_dist, 0.8);
  EXPECT_EQ(pid.pid.kp, 3.0);
}

namespace {
/// A 12 m row with an obstacle on it at x = 6, 22 s, from the row start: with the potential field and the
/// planned detours the body passes it; without avoidance (gain 0, no detours) it drives through it.
BenchScenario shortField(const TempDir& dir, bool avoid) {
  dir.write("short_field_config.yaml",
            "reference_generator:\n  type: field\n  field:\n    rows: 1\n    row_length: 12.0\n    start_y: 3.0\n"
            "  potential:\n    alpha: 4.0\n    beta: 4.0\n    gain: " +
                std::string(avoid ? "5.0" : "0.0") + "\n  obstacles:\n    - {x: 6.0, y: 3.0, radius: 0.3}\n");
  std::string text = readFile(kSuite + "/thesis_field.yaml");
  text = std::regex_replace(text, std::regex("name: thesis_field"), "name: short_field");
  text = std::regex_replace(text, std::regex("duration: 113.0"), "duration: 22.0");
  text =
      std::regex_replace(text, std::regex("config: \\.\\./field_thesis\\.yaml"),
                         "config: short_field_config.yaml\n  plan_detours: " + std::string(avoid ? "true" : "false"));
  text = std::regex_replace(text, std::regex("start: \\{x: -1.0, y: 0.0"), "start: {x: 0.0, y: 3.0");
  text = std::regex_replace(text, std::regex("start_d(x|y|theta): \\[[^\\]]*\\]"), "start_d$1: 0.0");
  text = std::regex_replace(text, std::regex("amplitude: \\[0.0, 2.0\\]"), "amplitude: 0.0");
  text = std::regex_replace(text, std::regex("cross_track_threshold: 0.05"), "cross_track_threshold: 10.0");
  text = std::regex_replace(text, std::regex("settle_time: 15.0"), "settle_time: 2.0");
  // Judged by the tracking rule: these runs are about the body, the finish and the governor, and the 2.4 m of the
  // row outside the obstacle's detour zone is too little to judge a sown share on.
  text = std::regex_replace(text, std::regex("cross_track_threshold: 10.0"),
                            "cross_track_threshold: 10.0\n  rule: tracking");
  return scenario_file::loadScenarioFile(dir.write("short_field.yaml", text));
}
}  // namespace

TEST(ScenarioLoader, AFieldRunFailsOnABodyContact) {
  TempDir dir;
  for (bool avoid : {true, false}) {
    SCOPED_TRACE(avoid ? "avoiding" : "driving through");
    BenchScenario b = shortField(dir, avoid);
    const std::vector<core::RunRow> rows = core::runBenchmark(b, 2, 2);
    for (const core::RunRow& r : rows) {
      if (avoid) {
        EXPECT_EQ(r.contacts, 0u);
        EXPECT_GT(r.min_clearance, 0.0);
        EXPECT_TRUE(r.success) << r.failure << ", end distance " << r.end_distance;
      } else {
        EXPECT_GE(r.contacts, 1u);
        EXPECT_LT(r.min_clearance, 0.0);
        EXPECT_FALSE(r.success);
        EXPECT_EQ(r.failure, "contact");
      }
    }
    const std::string report = core::reportSection(b.name, "kanayama+atsmc", rows);
    EXPECT_NE(report.find(avoid ? "contact 0" : "contact 2"), std::string::npos) << report;
  }
}

TEST(ScenarioLoader, AFieldRunCutShortIsNotFinished) {
  TempDir dir;
  BenchScenario b = shortField(dir, true);
  b.base.duration = 8.0;  // the path (12 m at 1 m/s and the ramp down) has not ended
  const std::vector<core::RunRow> rows = core::runBenchmark(b, 1, 1);
  EXPECT_EQ(rows[0].failure, "not finished");
}

// A profile (config/profiles/field.yaml) goes on top of a scenario's own blocks: its keys win, the
// scenario's other keys stay; a scenario without those blocks gets them; a typo in a profile is refused.
TEST(ScenarioLoader, AProfileGoesOnTopOfTheScenariosBlocks) {
  const std::string field = kSource + "/config/profiles/field.yaml";
  const BenchScenario wet = scenario_file::loadScenario("wet_soil", kSuite, field);
  ASSERT_TRUE(wet.realism);
  ASSERT_TRUE(wet.realism->traction);
  EXPECT_EQ(wet.realism->traction->draft_force, 10.0);  // the scenario's own key stays
  EXPECT_TRUE(wet.realism->motor.enabled);
  EXPECT_TRUE(wet.realism->traction_control.enabled);
  EXPECT_TRUE(wet.realism->speed_governor.enabled);
  EXPECT_EQ(wet.realism->feedback, core::Feedback::fused);
  EXPECT_TRUE(wet.realism->estimator.slip.detect);  // the slip-aware estimator (used with feedback fused)
  EXPECT_TRUE(wet.realism->hitch_control.enabled);
  EXPECT_FALSE(wet.realism->patches.empty());  // the field file's patches, with traction on
  EXPECT_FALSE(scenario_file::loadScenario("wet_soil", kSuite).realism->motor.enabled);
  EXPECT_FALSE(scenario_file::loadScenario("wet_soil", kSuite).realism->estimator.slip.detect);
  const BenchScenario line = scenario_file::loadScenario("thesis_line", kSuite, field);  // no blocks of its own
  ASSERT_TRUE(line.realism);
  EXPECT_TRUE(line.realism->traction);
  EXPECT_TRUE(line.realism->motor.enabled);
  EXPECT_EQ(line.validate(), "");
  TempDir dir;
  const std::string bad = dir.write("bad.yaml", "profile: {name: bad}\nplant_sim:\n  motor: {enabld: true}\n");
  try {
    scenario_file::loadScenario("wet_soil", kSuite, bad);
    ADD_FAILURE() << "not refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("motor/enabld"), std::string::npos) << e.what();
  }
  const std::string stray = dir.write("stray.yaml", "profile: {name: stray}\nduration: 3\n");
  EXPECT_THROW(scenario_file::loadScenario("wet_soil", kSuite, stray), std::invalid_argument);
  // A block a node does not own (the plant's motor under the torque controller) is refused by name.
  const std::string misplaced =
      dir.write("misplaced.yaml", "profile: {name: misplaced}\ntorque_controller:\n  motor: {enabled: true}\n");
  try {
    scenario_file::loadScenario("wet_soil", kSuite, misplaced);
    ADD_FAILURE() << "not refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("torque_controller/motor"), std::string::npos) << e.what();
  }
}

// The same profile onto an in-process configuration (Python's run_estimated(profile=)): its blocks over what the
// configuration holds, through the same reading as the benchmark's.
TEST(ScenarioLoader, AProfileAppliesToAnInProcessConfiguration) {
  const std::string field = scenario_file::resolveProfile("field", kSource).file;
  core::LoopConfig cfg;
  core::TractionParams wet;
  wet.mu_peak = 0.25;
  wet.mu_slide = 0.2;
  cfg.traction = wet;
  cfg.motor.stall_torque = 30.0;
  scenario_file::applyProfileTo(field, cfg);
  ASSERT_TRUE(cfg.traction);
  EXPECT_EQ(cfg.traction->mu_peak, 0.25);  // the caller's own key stays
  EXPECT_TRUE(cfg.motor.enabled);
  EXPECT_EQ(cfg.motor.stall_torque, 30.0);
  EXPECT_TRUE(cfg.traction_control.enabled);
  EXPECT_TRUE(cfg.speed_governor.enabled);
  EXPECT_EQ(cfg.feedback, core::Feedback::fused);
  EXPECT_EQ(cfg.validate(), "");
  core::LoopConfig bare;  // no traction of its own: the profile's with the defaults
  scenario_file::applyProfileTo(field, bare);
  ASSERT_TRUE(bare.traction);
  EXPECT_EQ(bare.traction->mu_peak, core::TractionParams().mu_peak);
}

// A profile is chosen as sim.launch profile:=NAME chooses it: config/profiles/NAME.yaml with its gains
// config/tuned/NAME/; a path is taken as it is, without gains; a name without a gains directory has none; an
// unknown name is refused with one line that lists the available ones.
TEST(ScenarioLoader, AProfileIsChosenByNameOrPath) {
  const scenario_file::ProfileFiles field = scenario_file::resolveProfile("field", kSource);
  EXPECT_EQ(field.file, kSource + "/config/profiles/field.yaml");
  EXPECT_EQ(field.gains_dir, kSource + "/config/tuned/field");
  const scenario_file::ProfileFiles path =
      scenario_file::resolveProfile(kSource + "/config/profiles/field.yaml", kSource);
  EXPECT_EQ(path.file, kSource + "/config/profiles/field.yaml");
  EXPECT_EQ(path.gains_dir, "");
  EXPECT_EQ(scenario_file::resolveProfile("mine.yaml", kSource).file, "mine.yaml");  // relative, as given
  EXPECT_EQ(scenario_file::resolveProfile("mine.yaml", kSource).gains_dir, "");

  TempDir tree;  // a source tree with two profiles, one with tuned gains
  ASSERT_EQ(
      std::system(("mkdir -p " + tree.path + "/config/profiles " + tree.path + "/config/tuned/tuned_one").c_str()), 0);
  tree.write("config/profiles/tuned_one.yaml", "profile: {name: tuned_one}\n");
  tree.write("config/profiles/bare.yaml", "profile: {name: bare}\n");
  EXPECT_EQ(scenario_file::resolveProfile("tuned_one", tree.path).gains_dir, tree.path + "/config/tuned/tuned_one");
  const scenario_file::ProfileFiles bare = scenario_file::resolveProfile("bare", tree.path);
  EXPECT_EQ(bare.file, tree.path + "/config/profiles/bare.yaml");
  EXPECT_EQ(bare.gains_dir, "");
  try {
    scenario_file::resolveProfile("nosuch", tree.path);
    ADD_FAILURE() << "an unknown name taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "unknown profile 'nosuch' (available in " + tree.path + "/config/profiles: bare, tuned_one)");
  }
  EXPECT_THROW(scenario_file::resolveProfile("feild", kSource), std::invalid_argument);
}

// tune's robust/profile takes a name too (the package's config/profiles), or a file relative to the config.
TEST(ScenarioLoader, ARobustTuningNamesItsProfile) {
  TempDir dir;
  const std::string head = "pso_tuner: {particles: 2, iterations: 0, controller: kanayama+atsmc}\nrobust:\n  profile: ";
  const std::string training = "\n  training:\n    - {scenario: " + kSuite + "/wet_line.yaml, runs: 1, base_seed: 1}\n";
  const scenario_file::TuneConfig by_name =
      scenario_file::loadTuneConfig(dir.write("name.yaml", head + "field" + training), "", kSource);
  const scenario_file::TuneConfig by_path = scenario_file::loadTuneConfig(
      dir.write("path.yaml", head + kSource + "/config/profiles/field.yaml" + training), "", kSource);
  const scenario_file::TuneConfig none = scenario_file::loadTuneConfig(
      dir.write("none.yaml",
                "pso_tuner: {particles: 2, iterations: 0, controller: kanayama+atsmc}\nrobust:" + training),
      "", kSource);
  for (const scenario_file::TuneConfig* c : {&by_name, &by_path}) {
    ASSERT_EQ(c->training.size(), 1u);
    ASSERT_TRUE(c->training[0].bench.realism);
    EXPECT_TRUE(c->training[0].bench.realism->motor.enabled);
    EXPECT_TRUE(c->training[0].bench.realism->traction_control.enabled);
    EXPECT_EQ(c->training[0].bench.realism->feedback, core::Feedback::fused);
  }
  EXPECT_FALSE(none.training[0].bench.realism->motor.enabled);
  // The shipped robust tuning names its profile.
  const scenario_file::TuneConfig shipped =
      scenario_file::loadTuneConfig(kSource + "/config/tuned/field/training.yaml", "", kSource);
  ASSERT_FALSE(shipped.training.empty());
  ASSERT_TRUE(shipped.training[0].bench.realism);
  EXPECT_TRUE(shipped.training[0].bench.realism->traction_control.enabled);
  try {
    scenario_file::loadTuneConfig(dir.write("typo.yaml", head + "feild" + training), "", kSource);
    ADD_FAILURE() << "an unknown profile name taken";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("robust/profile: unknown profile 'feild' (available in " + kSource + "/config/profiles: field"),
              std::string::npos)
        << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// The hitch control's block in a scenario or a profile, through its table; the field profile turns it on.
TEST(ScenarioLoader, TheHitchControlBlockIsRead) {
  const BenchScenario wet = scenario_file::loadScenario("wet_soil", kSuite, kSource + "/config/profiles/field.yaml");
  ASSERT_TRUE(wet.realism);
  EXPECT_TRUE(wet.realism->hitch_control.enabled);
  EXPECT_FALSE(scenario_file::loadScenario("wet_soil", kSuite).realism->hitch_control.enabled);
  TempDir dir;
  const std::string prof = dir.write("p.yaml",
                                     "profile: {name: p}\ntorque_controller: {traction_control: {enabled: true}, "
                                     "hitch_control: {enabled: true, lower_after: 7.5}}\n");
  const BenchScenario b = scenario_file::loadScenario("wet_soil", kSuite, prof);
  EXPECT_EQ(b.realism->hitch_control.lower_after, 7.5);
  // A block given twice is refused, not half taken (yaml-cpp's lookup finds the first).
  const std::string twice = dir.write("twice.yaml",
                                      "profile: {name: twice}\ntorque_controller: {traction_control: {enabled: true}}\n"
                                      "torque_controller: {hitch_control: {enabled: true}}\n");
  try {
    scenario_file::loadScenario("wet_soil", kSuite, twice);
    ADD_FAILURE() << "a repeated key taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("key 'torque_controller' appears twice (line 3)"), std::string::npos)
        << e.what();
  }
  const std::string bad =
      dir.write("bad.yaml", "profile: {name: bad}\ntorque_controller: {hitch_control: {lower_after: -1}}\n");
  try {
    scenario_file::loadScenario("wet_soil", kSuite, bad);
    ADD_FAILURE() << "not refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("hitch_control/lower_after"), std::string::npos) << e.what();
  }
}

// The command limits' block (kinematic_controller's limits/) in a scenario or a profile, through its table; the
// field profile turns them on with the table's bounds.
TEST(ScenarioLoader, TheCommandLimitsBlockIsRead) {
  const BenchScenario wet = scenario_file::loadScenario("wet_line", kSuite, kSource + "/config/profiles/field.yaml");
  ASSERT_TRUE(wet.realism);
  EXPECT_TRUE(wet.realism->limits.enabled);
  EXPECT_EQ(wet.realism->limits.max_acceleration, core::CommandLimitsParams().max_acceleration);
  EXPECT_FALSE(scenario_file::loadScenario("wet_line", kSuite).realism->limits.enabled);
  TempDir dir;
  const std::string prof =
      dir.write("p.yaml", "profile: {name: p}\nkinematic_controller: {limits: {enabled: true, max_v: 1.2}}\n");
  const BenchScenario b = scenario_file::loadScenario("thesis_line", kSuite, prof);  // a scenario without blocks
  ASSERT_TRUE(b.realism);
  EXPECT_TRUE(b.realism->limits.enabled);
  EXPECT_EQ(b.realism->limits.max_v, 1.2);
  for (const char* body : {"kinematic_controller: {limits: {max_v: 0}}", "kinematic_controller: {limits: {max_vv: 1}}",
                           "kinematic_controller: {kx: 2.0}"}) {
    const std::string bad = dir.write("bad.yaml", std::string("profile: {name: bad}\n") + body + "\n");
    try {
      scenario_file::loadScenario("wet_line", kSuite, bad);
      ADD_FAILURE() << "not refused: " << body;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_TRUE(what.find("limits/max_v") != std::string::npos ||
                  what.find("kinematic_controller/kx") != std::string::npos)
          << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

// A speed governor that slows the path's own time: a robot at its slowed target, short of the path's
// end when the run ends, has not finished (the finish check reads the reference's last time).
TEST(ScenarioLoader, ARunWhoseGovernedTargetHasNotReachedTheEndIsNotFinished) {
  TempDir dir;
  BenchScenario b = shortField(dir, true);
  const std::vector<core::RunRow> plain = core::runBenchmark(b, 1, 1);
  ASSERT_TRUE(plain[0].success) << plain[0].failure;
  core::FieldReference reference(b.field, b.obstacles);
  core::RunRow row = plain[0];
  reference.next(0.5 * reference.duration());  // the target half way along its path
  core::markNotFinished(row, reference, 2.0 * reference.duration(), b.finish_tolerance);
  EXPECT_EQ(row.failure, "not finished");
  row = plain[0];
  reference.next(reference.duration());
  core::markNotFinished(row, reference, 2.0 * reference.duration(), b.finish_tolerance);
  EXPECT_EQ(row.failure, "");
}
