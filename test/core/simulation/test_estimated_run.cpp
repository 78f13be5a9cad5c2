// The in-process loop with an estimate in it (core/simulation/runner.h) and the benchmark rows built on it
// (core/evaluation/estimated_bench.h): fed the truth it is runClosedLoop / the one loop with the plant's own state bit
// for bit; fed the EKF on the line its error stays bounded; fed the encoders it drifts under slip; the sensors' seed
// changes the sensor noise and nothing else; a benchmark row through it equals today's row; a robot that
// stalls on the patch is counted as not finished.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "sowing_robot/core/evaluation/benchmark.h"
#include "sowing_robot/core/evaluation/estimated_bench.h"
#include "sowing_robot/core/simulation/closed_loop.h"
#include "sowing_robot/core/simulation/runner.h"

using namespace sowing_robot::core;

namespace {

/// The thesis line with the mismatch, the disturbance (and a phase) and the wheel-torque noise: every input
/// the truth-fed loop must reproduce.
Scenario line(OuterKind outer, InnerKind inner, bool adaptive = true, double phase = 0.7) {
  Scenario sc;
  sc.duration = 6.0;
  sc.outer = outer;
  sc.inner = inner;
  sc.sliding.adaptive = adaptive;
  sc.disturbance.sinusoidal = true;
  sc.disturbance.amplitude = 1.0;
  sc.disturbance.mass_scale = 1.3;
  sc.disturbance.inertia_scale = 0.9;
  sc.disturbance.noise_std = 0.1;
  sc.disturbance.seed = 7;
  sc.disturbance_phase = phase;
  return sc;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expectSameRun(const RunResult& a, const RunResult& b) {
  for (int ax = 0; ax < AXIS_COUNT; ++ax) {
    EXPECT_TRUE(sameBits(a.metrics[ax].ise, b.metrics[ax].ise))
        << ax << ": " << a.metrics[ax].ise << " vs " << b.metrics[ax].ise;
    EXPECT_TRUE(sameBits(a.metrics[ax].itae, b.metrics[ax].itae)) << ax;
    EXPECT_TRUE(sameBits(a.metrics[ax].iae, b.metrics[ax].iae)) << ax;
  }
  for (int i = 0; i < a.final_state.size(); ++i)
    EXPECT_TRUE(sameBits(a.final_state[i], b.final_state[i]))
        << i << ": " << a.final_state[i] << " vs " << b.final_state[i];
  EXPECT_EQ(a.saturated_steps, b.saturated_steps);
  EXPECT_EQ(a.periods, b.periods);
  EXPECT_EQ(a.diverged, b.diverged);
}

}  // namespace

TEST(EstimatedRun, FedTheTruthItIsRunClosedLoopBitForBit) {
  for (auto pair : {std::make_tuple(OuterKind::kanayama, InnerKind::sliding_mode, true),
                    std::make_tuple(OuterKind::kanayama, InnerKind::sliding_mode, false),
                    std::make_tuple(OuterKind::kanayama, InnerKind::pid, true),
                    std::make_tuple(OuterKind::rpp, InnerKind::pid, true),
                    std::make_tuple(OuterKind::rpp, InnerKind::sliding_mode, true),
                    std::make_tuple(OuterKind::pure_pursuit, InnerKind::sliding_mode, true)}) {
    const Scenario sc = line(std::get<0>(pair), std::get<1>(pair), std::get<2>(pair));
    SCOPED_TRACE(sc.controllerName());
    LineReference ref;
    const RunResult today = runClosedLoop(sc, ref, true);
    LoopConfig cfg;  // ground_truth, no traction; the sensors run and are not looked at
    const LoopResult est = runClosedLoop(sc, cfg, ref, true);
    expectSameRun(est.run, today);
    EXPECT_TRUE(sameBits(est.run.metrics[AXIS_Y].settling_time, today.metrics[AXIS_Y].settling_time));
    EXPECT_LT(est.fed_error_max, 1e-12);  // the truth itself
  }
}

TEST(EstimatedRun, FedTheTruthOnTheTractionPlantItIsTheLoopOnThePlantsOwnStateBitForBit) {
  Scenario sc = line(OuterKind::kanayama, InnerKind::sliding_mode, true);
  TractionParams t;
  t.enabled = true;
  t.mu_peak = 0.35;
  t.mu_slide = 0.26;
  SoilPatch wet;
  wet.polygon = {{-5.0, -5.0}, {0.0, -5.0}, {0.0, 10.0}, {-5.0, 10.0}};  // round the start (x = -1)
  wet.mu_peak = 0.2;
  wet.mu_slide = 0.15;
  wet.rolling_resistance =
      0.15;  // soft: the patch changes the run (within the curve's linear part grip alone would not)
  LineReference ref;
  // The sensors' feed fed the truth against the plant's own state (closed_loop.h's StateFeed, no sensors).
  SlipPlant plant{TractionPlant(sc.robot, sc.disturbance, t), sc.robot.R};
  plant.plant.setSoil(SoilMap({wet}));
  StateFeed state_feed;
  Kanayama outer(sc.kanayama);
  SlidingModeController inner(sc.sliding, sc.robot);
  const std::function<void(const LoopSample&)> no_trace;
  const LoopResult today = closedLoop(sc, plant, state_feed, outer, inner, ref, true, no_trace, RunStop{});
  LoopConfig cfg;
  cfg.traction = t;
  cfg.patches = {wet};
  const LoopResult est = runClosedLoop(sc, cfg, ref, true);
  expectSameRun(est.run, today.run);
  EXPECT_TRUE(sameBits(est.max_abs_slip, today.max_abs_slip));
  EXPECT_GT(est.max_abs_slip, 0.0);
  // The patch is on the ground (without it the run differs).
  LoopConfig bare = cfg;
  bare.patches.clear();
  EXPECT_FALSE(sameBits(runClosedLoop(sc, bare, ref, true).run.metrics[AXIS_X].ise, today.run.metrics[AXIS_X].ise));
}

TEST(EstimatedRun, FedTheEkfOnTheLineItsErrorStaysBounded) {
  const Scenario sc = line(OuterKind::kanayama, InnerKind::sliding_mode, true, 0.0);
  Scenario longer = sc;
  longer.duration = 25.0;
  LoopConfig cfg;
  cfg.feedback = Feedback::fused;
  LineReference ref;
  const LoopResult est = runClosedLoop(longer, cfg, ref, false);
  ASSERT_FALSE(est.run.diverged);
  // The fix (sigma 2 cm at 10 Hz) bounds the estimate: a few centimetres, not metres.
  EXPECT_LT(est.fed_error_rms, 0.03) << est.fed_error_max;
  EXPECT_LT(est.fed_error_max, 0.10);
  EXPECT_GT(est.fed_error_rms, 1e-4);  // it is an estimate, not the truth
  EXPECT_GT(est.fixes.applied, 200);
  // Scored on the truth: the row is held to centimetres.
  EXPECT_LT(std::fabs(est.run.final_state[Y] - 3.0), 0.1);
  // The truth's ISE y is today's order of magnitude (not a lost loop).
  const RunResult truth = runClosedLoop(longer, ref, false);
  EXPECT_LT(est.run.metrics[AXIS_Y].ise, 2.0 * truth.metrics[AXIS_Y].ise + 0.5);
}

TEST(EstimatedRun, OdometryDriftsUnderSlipAndNotWithout) {
  Scenario sc = line(OuterKind::kanayama, InnerKind::sliding_mode, true, 0.0);
  sc.duration = 10.0;
  LineReference ref;
  LoopConfig dry;  // no-slip plant: only the quantisation
  const LoopResult a = runClosedLoop(sc, dry, ref, false);
  EXPECT_LT(a.odometry_error_max, 0.02);
  LoopConfig wet;
  TractionParams t;
  t.enabled = true;
  t.mu_peak = 0.2;
  t.mu_slide = 0.15;
  wet.traction = t;
  const LoopResult b = runClosedLoop(sc, wet, ref, false);
  EXPECT_GT(b.max_abs_slip, 0.1);
  EXPECT_GT(b.odometry_error_max, 10.0 * a.odometry_error_max);
  EXPECT_GT(b.odometry_error_max, 0.05);
  // Fed that odometry, the loop sees it and the truth pays.
  wet.feedback = Feedback::odometry;
  const LoopResult c = runClosedLoop(sc, wet, ref, false);
  EXPECT_GT(c.fed_error_max, 0.05);
}

TEST(EstimatedRun, TheSensorSeedChangesTheSensorNoiseOnly) {
  const Scenario sc = line(OuterKind::kanayama, InnerKind::sliding_mode, true, 0.0);
  LineReference ref;
  LoopConfig cfg;
  cfg.sensors.encoder.noise = 0.3;  // every sensor draws
  cfg.sensors.seed = 1;
  const LoopResult t1 = runClosedLoop(sc, cfg, ref, false);
  cfg.sensors.seed = 2;
  const LoopResult t2 = runClosedLoop(sc, cfg, ref, false);
  // Fed the truth: the run is the same whatever the sensors draw; the odometry is not.
  expectSameRun(t1.run, t2.run);
  EXPECT_FALSE(sameBits(t1.odometry_error_max, t2.odometry_error_max));
  // Fed the estimate: the seed changes the run, and the same seed repeats it to the bit.
  cfg.feedback = Feedback::fused;
  cfg.sensors.seed = 1;
  const LoopResult f1 = runClosedLoop(sc, cfg, ref, false);
  const LoopResult f1again = runClosedLoop(sc, cfg, ref, false);
  cfg.sensors.seed = 2;
  const LoopResult f2 = runClosedLoop(sc, cfg, ref, false);
  expectSameRun(f1.run, f1again.run);
  EXPECT_TRUE(sameBits(f1.fed_error_rms, f1again.fed_error_rms));
  EXPECT_FALSE(sameBits(f1.run.metrics[AXIS_Y].ise, f2.run.metrics[AXIS_Y].ise));
  EXPECT_FALSE(sameBits(f1.fed_error_rms, f2.fed_error_rms));
}

TEST(EstimatedRun, BadParametersAreRefusedNamingTheKey) {
  const Scenario sc = line(OuterKind::kanayama, InnerKind::sliding_mode);
  LineReference ref;
  LoopConfig cfg;
  cfg.sensors.fix.sigma = -1.0;
  try {
    runClosedLoop(sc, cfg, ref);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sensors/fix/sigma"), std::string::npos) << e.what();
  }
  cfg = LoopConfig();
  TractionParams t;
  t.mu_slide = 0.9;  // > mu_peak
  cfg.traction = t;
  EXPECT_THROW(runClosedLoop(sc, cfg, ref), std::invalid_argument);
  Feedback f;
  EXPECT_NE(parseFeedback("fusde", f).find("ground_truth, odometry, fused"), std::string::npos);
  EXPECT_EQ(parseFeedback("odometry", f), "");
  EXPECT_EQ(f, Feedback::odometry);
}

namespace {
BenchScenario benchLine() {
  BenchScenario b;
  b.name = "line";
  b.base.duration = 6.0;
  b.base.disturbance.frequency = 3.0;
  b.spec.settle_time = 3.0;
  return b;
}

/// A 12 m row with an obstacle at x = 6 (the loader test's short field), from the row start.
BenchScenario benchField() {
  BenchScenario b;
  b.name = "field";
  b.track = TrackKind::field;
  b.base.duration = 22.0;
  b.base.start = {0.0, 3.0, 0.0};
  b.field = FieldRunSetup().field;
  b.field.rows = 1;
  b.field.row_length = 12.0;
  b.field.start_y = 3.0;
  b.field.potential.beta = 4.0;
  b.obstacles = {Obstacle{6.0, 3.0, 0.3}};
  b.spec.start_dx = b.spec.start_dy = b.spec.start_dtheta = Uniform{0.0, 0.0};
  b.spec.amplitude = Uniform{0.0, 0.0};
  b.spec.cross_track_threshold = 10.0;
  b.spec.settle_time = 2.0;
  // The tracking rule: these rows are about the loop, the body and the finish; the plan ends with the axle at the
  // row's end, so the drill trailing it by 0.45 m leaves that much of a 12 m row (4 %) unsown.
  b.spec.rule = SuccessRule::tracking;
  return b;
}

void expectSameRows(const std::vector<RunRow>& a, const std::vector<RunRow>& b) {
  ASSERT_EQ(a.size(), b.size());
  // The CSV carries every figure at full precision: equal lines, equal rows.
  EXPECT_EQ(runsCsvLines("s", "c", a), runsCsvLines("s", "c", b));
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].cross_track_series, b[i].cross_track_series) << i;
}
}  // namespace

TEST(EstimatedBench, ATruthFedRowWithoutTractionIsTodaysRow) {
  for (BenchScenario b : {benchLine(), benchField()}) {
    SCOPED_TRACE(b.name);
    const std::vector<RunRow> today = runBenchmark(b, 3, 2);
    b.realism = LoopConfig();
    const std::vector<RunRow> through = runBenchmark(b, 3, 2);
    expectSameRows(through, today);
    EXPECT_TRUE(through[0].realism);
    EXPECT_FALSE(today[0].realism);
    // The realism columns only when asked; today's columns byte for byte otherwise.
    EXPECT_EQ(runsCsvHeader().find("sensor_seed"), std::string::npos);
    EXPECT_NE(runsCsvHeader(true).find(",sensor_seed,max_slip,"), std::string::npos);
  }
}

TEST(EstimatedBench, TheSensorSeedIsANewDrawThatLeavesTheOthersAlone) {
  const BenchScenario b = benchLine();
  const RunDraw d0 = drawRun(b.spec, b.base, 0), d1 = drawRun(b.spec, b.base, 1);
  EXPECT_NE(d0.sensor_seed, d1.sensor_seed);
  EXPECT_LE(d0.sensor_seed, 2147483647u);
  EXPECT_NE(d0.sensor_seed, d0.noise_seed);
  // Fused runs repeat alone from their draws, on one or two threads.
  BenchScenario f = benchLine();
  LoopConfig cfg;
  cfg.feedback = Feedback::fused;
  f.realism = cfg;
  f.requires_models = {"estimated_pose"};
  const std::vector<RunRow> one = runBenchmark(f, 3, 1), two = runBenchmark(f, 3, 2);
  expectSameRows(one, two);
  EXPECT_EQ(estimatedBenchRow(f, 2).fed_error_rms, one[2].fed_error_rms);
  // Run 2's sensors are seeded by its draw 8: the same run alone with that seed, not with the table's seed 1.
  const RunDraw d2 = drawRun(f.spec, f.base, 2);
  LoopConfig alone = cfg;
  alone.sensors.seed = d2.sensor_seed;
  LineReference ref(f.line_v_r, f.line_y, f.line_x0);
  EXPECT_EQ(runClosedLoop(applyDraw(f.base, f.spec, d2), alone, ref, false).fed_error_rms, one[2].fed_error_rms);
  alone.sensors.seed = 1;
  EXPECT_NE(runClosedLoop(applyDraw(f.base, f.spec, d2), alone, ref, false).fed_error_rms, one[2].fed_error_rms);
  EXPECT_GT(one[0].fed_error_rms, 0.0);
  EXPECT_NE(runsCsvLines("s", "c", one, true).find("," + std::to_string(d0.sensor_seed) + ","), std::string::npos);
}

TEST(EstimatedBench, RequiredModelsMustBeSwitchedOn) {
  BenchScenario b = benchLine();
  b.requires_models = {"wet_soil"};
  EXPECT_NE(b.validate().find("traction is not enabled"), std::string::npos) << b.validate();
  b.requires_models = {"estimated_pose"};
  EXPECT_NE(b.validate().find("feedback is ground_truth"), std::string::npos) << b.validate();
  b.realism = LoopConfig();
  b.realism->feedback = Feedback::fused;
  EXPECT_EQ(b.validate(), "");
  b.requires_models = {"dry_soil"};
  EXPECT_NE(b.validate().find("dry_soil"), std::string::npos);
}

TEST(EstimatedBench, ARobotThatStallsOnThePatchIsNotFinished) {
  BenchScenario b = benchField();
  b.obstacles.clear();
  LoopConfig cfg;
  TractionParams t;
  t.enabled = true;
  t.draft_force = 60.0;  // a furrow opener in heavy soil
  cfg.traction = t;
  const std::vector<RunRow> dry = runBenchmark(b, 1, 1);
  b.realism = cfg;
  const std::vector<RunRow> grip = runBenchmark(b, 1, 1);
  EXPECT_TRUE(grip[0].success) << grip[0].failure;  // on loose moist soil the draft is pulled
  // Ice over the second half of the row: the wheels spin, the robot stops short of the end.
  SoilPatch ice;
  ice.polygon = {{6.0, 0.0}, {20.0, 0.0}, {20.0, 6.0}, {6.0, 6.0}};
  ice.mu_peak = 0.05;
  ice.mu_slide = 0.04;
  b.realism->patches = {ice};
  const std::vector<RunRow> stall = runBenchmark(b, 1, 1);
  EXPECT_TRUE(dry[0].success) << dry[0].failure;
  EXPECT_FALSE(stall[0].success);
  EXPECT_EQ(stall[0].failure, "not finished");
  EXPECT_GT(stall[0].end_distance, 1.0);
  EXPECT_GT(stall[0].max_slip, 0.5);
  EXPECT_GT(stall[0].tool_down_time, 0.0);
}

// The thesis line's soil made wet (mu 0.2 / 0.15) on the traction plant, with the motors on.
LoopConfig wetLineWithMotors() {
  LoopConfig cfg;
  TractionParams wet;
  wet.mu_peak = 0.2;
  wet.mu_slide = 0.15;
  cfg.traction = wet;
  cfg.motor.enabled = true;
  return cfg;
}

// The drive-train layers in the loop, on the thesis line over wet soil (mu 0.2) with the motors on: the
// traction control keeps the wheels near the friction peak where the bare loop spins them, and the speed
// governor slows the target while it does. With every layer off the run is the run without them (the
// suites' runs.csv are compared byte for byte for that).
TEST(EstimatedRun, TractionControlKeepsTheWheelsNearThePeak) {
  Scenario sc = line(OuterKind::kanayama, InnerKind::sliding_mode, true);
  sc.duration = 8.0;
  LoopConfig cfg = wetLineWithMotors();
  LineReference ref;
  const LoopResult bare = runClosedLoop(sc, cfg, ref, false);
  cfg.traction_control.enabled = true;
  const LoopResult tc = runClosedLoop(sc, cfg, ref, false);
  cfg.speed_governor.enabled = true;
  const LoopResult governed = runClosedLoop(sc, cfg, ref, false);
  std::printf("max slip: bare %.3f, traction control %.3f (slipping %.2f s), governed %.3f (slowest rate %.2f)\n",
              bare.max_abs_slip, tc.max_abs_slip, tc.traction_control_time, governed.max_abs_slip,
              governed.governor_min_rate);
  EXPECT_GT(bare.max_abs_slip, 1.0);  // the bare loop spins the wheels
  EXPECT_LT(tc.max_abs_slip, 0.5 * bare.max_abs_slip);
  EXPECT_GT(tc.traction_control_time, 0.0);
  EXPECT_EQ(bare.governor_min_rate, 1.0);
  EXPECT_LT(governed.governor_min_rate, 1.0);
  cfg.traction_control.enabled = false;
  EXPECT_THROW(runClosedLoop(sc, cfg, ref, false), std::invalid_argument);  // a governor needs the control
}

// governed_time_back (the benchmark's field runs): a run the governor slowed lasts until the governed path
// time has run the scenario's duration, so the path is judged at the same point as an ungoverned one; without
// it the run ends at the duration with the target short of it. Never longer than twice the duration.
TEST(EstimatedRun, AGovernedRunGetsTheTimeTheGovernorTookBack) {
  Scenario sc = line(OuterKind::kanayama, InnerKind::sliding_mode, true);
  sc.duration = 8.0;
  LoopConfig cfg = wetLineWithMotors();
  cfg.traction_control.enabled = true;
  cfg.speed_governor.enabled = true;
  LineReference plain_ref, back_ref;
  const LoopResult plain = runClosedLoop(sc, cfg, plain_ref, false);
  cfg.governed_time_back = true;
  const LoopResult back = runClosedLoop(sc, cfg, back_ref, false);
  std::printf(
      "governed: slowest rate %.2f; periods %ld without, %ld with the time back (duration %ld); path time "
      "%.3f s / %.3f s\n",
      plain.governor_min_rate, static_cast<long>(plain.run.periods), static_cast<long>(back.run.periods),
      static_cast<long>(sc.steps()), plain_ref.lastTime(), back_ref.lastTime());
  ASSERT_LT(plain.governor_min_rate, 1.0);  // the governor did slow the target
  EXPECT_EQ(plain.run.periods, sc.steps());
  EXPECT_LT(plain_ref.lastTime(), sc.duration - 0.1);  // the target short of the path's time
  EXPECT_GT(back.run.periods, plain.run.periods);
  EXPECT_LE(back.run.periods, 2 * sc.steps());
  EXPECT_GE(back_ref.lastTime(), sc.duration - 0.01);  // the path has run its duration (to within a period)
}

// The hitch tests' line (kanayama+pid, 14 s): a 25 N draft on an open-ended row along it, a wet patch from x = 4 to
// 9 m (mu 0.2, rolling resistance 0.08), the motors and the traction control on (raising the tool at 10 /s).
Scenario hitchLine() {
  Scenario sc = line(OuterKind::kanayama, InnerKind::pid);
  sc.duration = 14.0;
  return sc;
}

LoopConfig hitchPatch() {
  LoopConfig cfg;
  TractionParams t;
  t.draft_force = 25.0;
  cfg.traction = t;
  SoilPatch wet;
  wet.polygon = {{4.0, 0.0}, {9.0, 0.0}, {9.0, 6.0}, {4.0, 6.0}};
  wet.mu_peak = 0.2;
  wet.mu_slide = 0.15;
  wet.rolling_resistance = 0.08;
  cfg.patches = {wet};
  cfg.tool_rows = {RowSegment{Eigen::Vector2d(0.0, 3.0), Eigen::Vector2d(100.0, 3.0)}};
  cfg.tool_rows_open_ended = true;
  cfg.motor.enabled = true;
  cfg.traction_control.enabled = true;
  cfg.traction_control.raise_rate = 10.0;
  return cfg;
}

// Slip-limit hitch control in the loop (FIELD.md's grip budget): on a patch where the wheels' peak grip
// cannot pull the tool's draft (mu 0.2 at mass 1.3: 38.7 N against 18.4 N of rolling resistance plus a 25 N
// draft) the robot with the tool kept down stalls behind its target; with the hitch the traction control's
// grip verdict raises the tool, the robot crosses, and the row it left unsown is counted. The hitch needs
// the traction control.
TEST(EstimatedRun, TheHitchControlLiftsTheToolThroughAPatchTheDraftCannotBePulledAcross) {
  const Scenario sc = hitchLine();
  LoopConfig cfg = hitchPatch();
  LineReference ref;
  const LoopResult down = runClosedLoop(sc, cfg, ref, false);
  cfg.hitch_control.enabled = true;
  const LoopResult hitch = runClosedLoop(sc, cfg, ref, false);
  std::printf("end x: tool kept down %.2f m, hitch %.2f m (raised %d times, %.2f m unsown, tool down %.1f s)\n",
              down.run.final_state[X], hitch.run.final_state[X], hitch.hitch_raises, hitch.unsown_distance,
              hitch.tool_down_time);
  EXPECT_LT(down.run.final_state[X], 9.0);  // stalled on the patch
  EXPECT_EQ(down.unsown_distance, 0.0);
  EXPECT_EQ(down.hitch_raises, 0);
  EXPECT_GT(hitch.run.final_state[X], 13.0);  // crossed it and caught up with the target
  EXPECT_GE(hitch.hitch_raises, 1);
  EXPECT_GT(hitch.unsown_distance, 2.0);  // the patch's rows, at least in part
  EXPECT_LT(hitch.unsown_distance, 14.0);
  EXPECT_LT(hitch.tool_down_time, down.tool_down_time);
  cfg.traction_control.enabled = false;
  EXPECT_THROW(runClosedLoop(sc, cfg, ref, false), std::invalid_argument);
}

// Depth control in the loop, on the hitch test's patch (mu 0.2 at mass 1.3: 38.7 N of peak grip against 18.4 N of
// rolling resistance plus 25 N of draft at the nominal 4 cm): run at 2 cm the draft is 12.5 N and the grip
// carries it, so the drill runs through the patch shallower instead of being lifted, and leaves far less of the
// row unsown than the hitch alone. The trace's tool_depth is 0 with the tool up and the nominal depth without
// depth control.
TEST(EstimatedRun, DepthControlRunsTheDrillShallowerBeforeLiftingIt) {
  const Scenario sc = hitchLine();
  LoopConfig cfg = hitchPatch();
  cfg.hitch_control.enabled = true;
  struct Depths {
    double min_down = 1.0, max_down = 0.0;
    bool up_is_zero = true;
  };
  const auto trace = [](Depths& d) {
    return [&d](const EstimatedSample& e) {
      if (e.tool_down) {
        d.min_down = std::min(d.min_down, e.tool_depth);
        d.max_down = std::max(d.max_down, e.tool_depth);
      } else if (e.tool_depth != 0.0) {
        d.up_is_zero = false;
      }
    };
  };
  LineReference ref;
  Depths hitch_depths, depth_depths;
  const LoopResult hitch = runClosedLoop(sc, cfg, ref, false, trace(hitch_depths));
  cfg.seeding.depth_min = 0.02;  // a band down to 2 cm
  cfg.hitch_control.depth_control = true;
  cfg.hitch_control.depth_shallowest = 0.02;
  const LoopResult depth = runClosedLoop(sc, cfg, ref, false, trace(depth_depths));
  std::printf(
      "hitch alone: %.2f m unsown (%d raises); depth control: %.2f m unsown (%d raises), depth %.3f..%.3f m, "
      "mean sowing depth %.4f m, end x %.2f m\n",
      hitch.unsown_distance, hitch.hitch_raises, depth.unsown_distance, depth.hitch_raises, depth_depths.min_down,
      depth_depths.max_down, depth.meanSowingDepth(), depth.run.final_state[X]);
  EXPECT_EQ(hitch_depths.min_down, cfg.traction->draft_depth);  // no depth control: the nominal depth throughout
  EXPECT_EQ(hitch_depths.max_down, cfg.traction->draft_depth);
  EXPECT_TRUE(hitch_depths.up_is_zero);
  EXPECT_TRUE(depth_depths.up_is_zero);
  EXPECT_NEAR(depth_depths.min_down, 0.02, 1e-4);  // down to the band's shallowest (deepening from there)
  EXPECT_EQ(depth_depths.max_down, 0.04);
  EXPECT_LT(depth.meanSowingDepth(), 0.04);
  EXPECT_GT(depth.run.final_state[X], 13.0);  // crossed
  EXPECT_LT(depth.unsown_distance, 0.5 * hitch.unsown_distance);
  // Both raise the tool once on the start's acceleration (the hitch follows the verdict whether or not the tool
  // is down: torque_controller cannot see the drill's rule); only the hitch alone raises it again in the patch.
  EXPECT_LT(depth.hitch_raises, hitch.hitch_raises);
  // Depths outside the agronomic band are refused.
  cfg.hitch_control.depth_shallowest = 0.01;
  EXPECT_NE(cfg.validate().find("agronomic band"), std::string::npos) << cfg.validate();
}

// The traction control's anti-windup reaches the inner loop: with it the run differs (the integrators
// hold while a torque is held back), without it the run is the one of today's layers bit for bit.
TEST(EstimatedRun, TheTractionControlsAntiWindupReachesTheInnerLoop) {
  Scenario sc = line(OuterKind::kanayama, InnerKind::pid);
  LoopConfig cfg = wetLineWithMotors();
  cfg.traction_control.enabled = true;
  LineReference ref;
  const LoopResult plain = runClosedLoop(sc, cfg, ref, false);
  const LoopResult again = runClosedLoop(sc, cfg, ref, false);
  expectSameRun(plain.run, again.run);
  cfg.traction_control.anti_windup = true;
  const LoopResult held = runClosedLoop(sc, cfg, ref, false);
  EXPECT_FALSE(sameBits(plain.run.final_state[X], held.run.final_state[X]));
}
