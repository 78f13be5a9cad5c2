// Monte-Carlo runner (core/evaluation/benchmark.h): seed-indexed draws, rows independent of the thread count,
// failures counted with their reason, statistics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sowing_robot/core/evaluation/benchmark.h"
#include "sowing_robot/core/evaluation/run_metrics.h"

using namespace sowing_robot::core;

namespace {
Scenario shortLine(const char* pair) {
  Scenario sc;
  sc.duration = 4.0;
  EXPECT_EQ(parseControllerPair(pair, sc.outer, sc.inner, sc.sliding.adaptive), "");
  return sc;
}
MonteCarloSpec shortSpec() {
  MonteCarloSpec spec;
  spec.settle_time = 3.0;
  spec.cross_track_threshold = 10.0;  // judged on divergence only here
  return spec;
}
void expectSameRows(const std::vector<RunRow>& a, const std::vector<RunRow>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].draw.mass_scale, b[i].draw.mass_scale) << i;
    EXPECT_EQ(a[i].draw.noise_seed, b[i].draw.noise_seed) << i;
    EXPECT_EQ(a[i].draw.start_theta, b[i].draw.start_theta) << i;
    const std::vector<double> va = metricValues(a[i]), vb = metricValues(b[i]);
    ASSERT_EQ(va.size(), vb.size());
    for (std::size_t c = 0; c < va.size(); ++c)
      if (!(std::isnan(va[c]) && std::isnan(vb[c]))) EXPECT_EQ(va[c], vb[c]) << i << " " << metricColumns()[c];
    EXPECT_EQ(a[i].success, b[i].success) << i;
  }
}
}  // namespace

TEST(Benchmark, OneAndTwoThreadsGiveIdenticalRows) {
  for (const char* pair : {"kanayama+atsmc", "rpp+pid"}) {
    const Scenario sc = shortLine(pair);
    LineReference line;
    const std::vector<RunRow> one = runMonteCarlo(sc, line, shortSpec(), 6, 1);
    const std::vector<RunRow> two = runMonteCarlo(sc, line, shortSpec(), 6, 2);
    expectSameRows(one, two);
    EXPECT_EQ(runsCsvLines("thesis_line", pair, one), runsCsvLines("thesis_line", pair, two));
  }
}

TEST(Benchmark, ARunDependsOnItsSeedOnlyAndCanBeRepeatedAlone) {
  const Scenario sc = shortLine("kanayama+atsmc");
  LineReference line;
  // 5 runs: two pairs run in lockstep, and the last run alone.
  const std::vector<RunRow> rows = runMonteCarlo(sc, line, shortSpec(), 5, 2);
  // Each run again, alone, from its draw: the same integrals to the bit.
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const RunResult r = runClosedLoop(applyDraw(sc, shortSpec(), rows[i].draw), line);
    for (int a = 0; a < AXIS_COUNT; ++a) {
      EXPECT_EQ(r.metrics[a].ise, rows[i].metrics[a].ise) << i << " " << a;
      EXPECT_EQ(r.metrics[a].itae, rows[i].metrics[a].itae) << i << " " << a;
    }
  }
  // Different seeds draw differently, within the stated bounds.
  EXPECT_NE(rows[0].draw.mass_scale, rows[1].draw.mass_scale);
  const MonteCarloSpec spec = shortSpec();
  for (const RunRow& row : rows) {
    EXPECT_GE(row.draw.mass_scale, spec.mass_scale.lo);
    EXPECT_LE(row.draw.mass_scale, spec.mass_scale.hi);
    EXPECT_GE(row.draw.amplitude, spec.amplitude.lo);
    EXPECT_LE(row.draw.amplitude, spec.amplitude.hi);
    EXPECT_GE(row.draw.start_x, sc.start.x + spec.start_dx.lo);
    EXPECT_LE(row.draw.start_x, sc.start.x + spec.start_dx.hi);
    EXPECT_GT(row.effort, 0.0);
    EXPECT_GT(row.chattering, 0.0);
  }
  // The draws do not depend on how many runs are asked for.
  EXPECT_EQ(drawRun(spec, sc, 3).phase, rows[3].draw.phase);
}

// A line row's per-period figures are a RunTally the loop adds up itself (no callback): the same bits as
// a trace callback calling add() every period, for both inner-controller kinds (PID: another loop).
TEST(Benchmark, TheTallyInTheLoopEqualsTheTallyFedByACallback) {
  for (const char* pair : {"kanayama+atsmc", "rpp+pid"}) {
    const Scenario base = shortLine(pair);
    const MonteCarloSpec spec = shortSpec();
    const Scenario sc = applyDraw(base, spec, drawRun(spec, base, 2));
    std::vector<double> series_in, series_cb;
    RunTally in, cb;
    for (RunTally* t : {&in, &cb}) {
      t->dt = secondsFromNanos(sc.control_period_ns);
      t->settle_time = 1.0;
      t->series_every = 7;
    }
    in.series = &series_in;
    cb.series = &series_cb;
    LineReference line;
    const RunResult a = runClosedLoop(sc, line, true, in);
    const RunResult b = runClosedLoop(sc, line, true, [&cb](const LoopSample& s) { cb.add(s); });
    EXPECT_GT(in.effort, 0.0) << pair;
    EXPECT_GT(in.worst_cross_track, 0.0) << pair;
    EXPECT_EQ(in.effort, cb.effort) << pair;
    EXPECT_EQ(in.chattering, cb.chattering) << pair;
    EXPECT_EQ(in.worst_cross_track, cb.worst_cross_track) << pair;
    EXPECT_EQ(in.last_cross_track, cb.last_cross_track) << pair;
    EXPECT_EQ(series_in.size(), static_cast<std::size_t>(sc.steps() / 7 + 1)) << pair;
    EXPECT_EQ(series_in, series_cb) << pair;
    EXPECT_EQ(a.periods, b.periods) << pair;
    EXPECT_EQ(a.saturated_steps, b.saturated_steps) << pair;
    EXPECT_EQ(a.metrics[AXIS_Y].itae, b.metrics[AXIS_Y].itae) << pair;
    EXPECT_EQ(a.metrics[AXIS_THETA].settling_time, b.metrics[AXIS_THETA].settling_time) << pair;
  }
}

TEST(Benchmark, AFailedRunIsCountedWithItsReason) {
  Scenario sc = shortLine("kanayama+atsmc");
  LineReference line;
  MonteCarloSpec spec = shortSpec();
  spec.cross_track_threshold = 1e-9;  // nobody is that good
  const std::vector<RunRow> rows = runMonteCarlo(sc, line, spec, 3, 1);
  for (const RunRow& r : rows) {
    EXPECT_FALSE(r.success);
    EXPECT_EQ(r.failure, "cross-track");
  }
  EXPECT_NE(reportSection("thesis_line", "kanayama+atsmc", rows).find("success 0 (0 %)"), std::string::npos);
}

TEST(Benchmark, TheDisturbancePhaseShiftsThePlantsClock) {
  Scenario sc = shortLine("kanayama+atsmc");
  sc.disturbance.sinusoidal = true;
  LineReference line;
  const RunResult zero = runClosedLoop(sc, line, false);
  sc.disturbance_phase = 1.0;
  const RunResult shifted = runClosedLoop(sc, line, false);
  EXPECT_NE(zero.final_state, shifted.final_state);
  sc.disturbance_phase = 2.0 * M_PI;  // a whole period: the same disturbance up to rounding
  const RunResult whole = runClosedLoop(sc, line, false);
  EXPECT_NEAR(whole.final_state[Y], zero.final_state[Y], 1e-6);
}

TEST(Benchmark, BadRequestsAreRefusedNamingWhy) {
  const Scenario sc = shortLine("kanayama+atsmc");
  LineReference line;
  EXPECT_THROW(runMonteCarlo(sc, line, shortSpec(), 0, 1), std::invalid_argument);
  MonteCarloSpec spec = shortSpec();
  spec.mass_scale = {1.5, 0.8};
  try {
    runMonteCarlo(sc, line, spec, 2, 1);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mass_scale"), std::string::npos) << e.what();
  }
}

// A draw range the spec accepts (> 0) but the plant does not (mass_scale within [0.1, 10]): refused
// before any run starts, naming the first run whose draw is out and the plant's reason, by both runners.
TEST(Benchmark, ADrawThePlantRefusesStopsTheRunsBeforeAnyStarts) {
  MonteCarloSpec spec = shortSpec();
  spec.mass_scale = {5.0, 20.0};  // two thirds of the draws above 10
  ASSERT_EQ(spec.validate(), "");
  BenchScenario b;
  b.name = "heavy";
  b.base = shortLine("kanayama+atsmc");
  b.spec = spec;
  ASSERT_EQ(b.validate(), "");
  // Run 0 alone may draw in range; among 20 runs some draw above 10 for any seed.
  std::int64_t calls = 0;
  const auto count = [&](std::int64_t) { ++calls; };
  LineReference line;
  for (int runner = 0; runner < 2; ++runner) {
    SCOPED_TRACE(runner == 0 ? "runMonteCarlo" : "runBenchmark");
    try {
      if (runner == 0)
        runMonteCarlo(b.base, line, spec, 20, 2, count);
      else
        runBenchmark(b, 20, 2, count);
      FAIL() << "no refusal";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("a drawn run does not validate: ", 0), 0u) << what;
      EXPECT_NE(what.find("mass_scale"), std::string::npos) << what;
    }
  }
  EXPECT_EQ(calls, 0) << "runs started before the refusal";
  // The same spec with the range inside the plant's runs.
  spec.mass_scale = {5.0, 10.0};
  EXPECT_EQ(runMonteCarlo(b.base, line, spec, 2, 1).size(), 2u);
}

TEST(Benchmark, StatisticsCountDivergedRunsAndSkipMissingFigures) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  Statistic s = statistic({1.0, 2.0, 3.0, 4.0});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(5.0 / 3.0));
  EXPECT_DOUBLE_EQ(s.p95, 4.0);
  EXPECT_DOUBLE_EQ(s.worst, 4.0);
  s = statistic({1.0, inf});
  EXPECT_EQ(s.mean, inf);
  EXPECT_EQ(s.worst, inf);
  s = statistic({1.0, nan, 3.0});
  EXPECT_DOUBLE_EQ(s.mean, 2.0);
  std::vector<double> hundred;
  for (int i = 1; i <= 100; ++i) hundred.push_back(i);
  EXPECT_DOUBLE_EQ(statistic(hundred).p95, 95.0);
}

TEST(Benchmark, TheSineRowsHeadingSpeedAndYawRateAreTheDerivativesOfItsPath) {
  SineRowParams p;
  SineReference ref(p);
  const double h = 1e-6;
  for (double t : {0.3, 2.0, 4.7, 7.5}) {
    SineReference a(p), b(p), c(p);
    const Reference r0 = a.next(t - h), r = b.next(t), r1 = c.next(t + h);
    const double dx = (r1.pose.x - r0.pose.x) / (2 * h), dy = (r1.pose.y - r0.pose.y) / (2 * h);
    EXPECT_NEAR(r.v, std::hypot(dx, dy), 1e-6) << t;
    EXPECT_NEAR(r.pose.theta, std::atan2(dy, dx), 1e-6) << t;
    EXPECT_NEAR(r.omega, (r1.pose.theta - r0.pose.theta) / (2 * h), 1e-5) << t;
    EXPECT_NEAR(r.v_dot, (r1.v - r0.v) / (2 * h), 1e-5) << t;
    EXPECT_NEAR(r.omega_dot, (r1.omega - r0.omega) / (2 * h), 1e-4) << t;
  }
  SineRowParams bad;
  bad.wavelength = -1.0;
  EXPECT_NE(bad.validate(), "");
}

TEST(Benchmark, AFieldBenchmarkGivesTheSameRowsOnOneAndTwoThreads) {
  BenchScenario b;
  b.name = "small_field";
  b.track = TrackKind::field;
  b.base.duration = 14.0;
  b.base.start = {0.0, 3.0, 0.0};
  b.field.rows = 1;
  b.field.row_length = 10.0;
  b.field.start_y = 3.0;
  b.field.potential.beta = 4.0;
  b.obstacles = {{5.0, 3.0, 0.3}};
  b.spec.start_dx = b.spec.start_dy = b.spec.start_dtheta = {0.0, 0.0};
  b.spec.settle_time = 2.0;
  ASSERT_EQ(b.validate(), "");
  const std::vector<RunRow> one = runBenchmark(b, 3, 1), two = runBenchmark(b, 3, 2);
  expectSameRows(one, two);
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].min_clearance, two[i].min_clearance);
    EXPECT_EQ(one[i].cross_track_series, two[i].cross_track_series);
    EXPECT_FALSE(one[i].cross_track_series.empty());
  }
  EXPECT_EQ(envelopeCsvLines("f", "c", crossTrackEnvelope(one, b.envelope_period)),
            envelopeCsvLines("f", "c", crossTrackEnvelope(two, b.envelope_period)));
  // The series is sampled every envelope period from t = 0 (steps 0, 100, ... at 1 kHz).
  const std::size_t expected = static_cast<std::size_t>(std::floor((b.base.duration + approachExtraTime([&] {
                                                                      FieldRunSetup s;
                                                                      s.field = b.field;
                                                                      s.field.start_pose = b.base.start;
                                                                      s.obstacles = b.obstacles;
                                                                      return s;
                                                                    }())) /
                                                                       b.envelope_period +
                                                                   1e-9)) +
                               1;
  EXPECT_NEAR(static_cast<double>(one[0].cross_track_series.size()), static_cast<double>(expected), 1.0);
}

TEST(Benchmark, WorkerLoadsCountEveryRunOnceAndLeaveTheRowsAlone) {
  BenchScenario b;
  b.name = "short_line";
  b.base = shortLine("kanayama+atsmc");
  b.spec = shortSpec();
  ASSERT_EQ(b.validate(), "");
  const std::vector<RunRow> plain = runBenchmark(b, 7, 2);
  // 7 runs: 8 threads are cut to 7 workers.
  for (const int threads : {1, 2, 5, 8}) {
    SCOPED_TRACE(threads);
    std::vector<WorkerLoad> loads{{99, -1.0}};  // overwritten, not appended to
    const std::vector<RunRow> rows = runBenchmark(b, 7, threads, {}, &loads);
    expectSameRows(plain, rows);
    ASSERT_EQ(loads.size(), static_cast<std::size_t>(std::min(threads, 7)));
    std::int64_t runs = 0;
    for (const WorkerLoad& w : loads) {
      runs += w.runs;
      EXPECT_GE(w.cpu_seconds, 0.0);
      EXPECT_TRUE(std::isfinite(w.cpu_seconds));
    }
    EXPECT_EQ(runs, 7);
    if (threads == 1) EXPECT_GT(loads[0].cpu_seconds, 0.0);  // 7 runs of 4 s at 1 kHz take CPU time
  }
}

TEST(Benchmark, EnvelopeQuantilesAreNearestRankPerSampleTime) {
  std::vector<RunRow> rows(4);
  for (int i = 0; i < 4; ++i) rows[i].cross_track_series = {static_cast<double>(i), -static_cast<double>(i)};
  rows[3].cross_track_series.push_back(7.0);  // one longer run: alone at the third sample
  const Envelope e = crossTrackEnvelope(rows, 0.5);
  ASSERT_EQ(e.p50.size(), 3u);
  EXPECT_EQ(e.p50[0], 1.0);  // ranks of {0, 1, 2, 3}: ceil(0.5 * 4) = 2nd
  EXPECT_EQ(e.p95[0], 3.0);
  EXPECT_EQ(e.p05[1], -3.0);
  EXPECT_EQ(e.max_abs[1], 3.0);
  EXPECT_EQ(e.p50[2], 7.0);
}

namespace {
std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ',')) out.push_back(field);
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}
std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}
/// A row with every field set, realism included: what the farm must carry across ranks.
RunRow fullRow() {
  RunRow r;
  r.draw = drawRun(MonteCarloSpec{}, Scenario{}, 7);
  double v = 0.125;
  for (AxisMetrics& m : r.metrics)
    for (double* f : {&m.ise, &m.itse, &m.iae, &m.itae, &m.rise_time, &m.settling_time, &m.overshoot, &m.peak})
      *f = (v *= 1.7);
  r.metrics[AXIS_X].rise_time = std::numeric_limits<double>::quiet_NaN();
  r.effort = 1.0 / 3.0;
  r.chattering = std::numeric_limits<double>::infinity();
  r.time_at_limit = 0.004;
  r.worst_cross_track = 0.01;
  r.final_cross_track = 0.002;
  r.contacts = 3;
  r.min_clearance = -0.01;
  r.end_distance = 0.3;
  r.diverged = false;
  r.success = false;
  r.failure = "no traction at (1.5 3): slip";
  r.cross_track_series = {0.5, -0.25, 1e-9};
  r.realism = true;
  r.max_slip = 0.7;
  r.high_slip_share = 0.04;
  r.tool_down_time = 12.5;
  r.fed_error_rms = 0.02;
  r.fed_error_max = 0.05;
  r.odometry_error_max = 0.9;
  r.fixes_applied = 41;
  r.fixes_refused = 2;
  r.unsown_distance = 1.25;
  r.seeds_unsown = 25.0;
  return r;
}
}  // namespace

// The registry (run_metrics.h) is what names a metric: one entry per name, each with a unit, a label and
// a meaning, and no name that is also an identity column of runs.csv.
TEST(RunMetrics, NamesAreUniqueAndEachHasAUnitALabelAndAMeaning) {
  std::set<std::string> names(runsCsvIdentityColumns().begin(), runsCsvIdentityColumns().end());
  ASSERT_EQ(names.size(), runsCsvIdentityColumns().size());
  ASSERT_FALSE(runMetrics().empty());
  for (const RunMetric& m : runMetrics()) {
    EXPECT_TRUE(names.insert(m.name).second) << m.name << " twice, or also an identity column";
    EXPECT_FALSE(m.unit.empty()) << m.name;
    EXPECT_FALSE(m.label.empty()) << m.name;
    EXPECT_FALSE(m.meaning.empty()) << m.name;
    EXPECT_EQ(m.meaning.find('\n'), std::string::npos) << m.name << ": one line";
    EXPECT_TRUE(m.get && m.set) << m.name;
    EXPECT_EQ(m.name.find(','), std::string::npos) << m.name;
  }
  // The report's table is the registry's report_table entries.
  EXPECT_EQ(metricColumns().size(), 34u);
  EXPECT_EQ(metricColumns().front(), "ise_x");
  EXPECT_EQ(metricColumns().back(), "unsown_mid_row");
}

// Every column of runs.csv (a tiny benchmark, and the realism columns) is a registry entry or one of the
// documented identity columns (who ran, what was drawn, why it failed), and every row has one value per column.
TEST(RunMetrics, EveryRunsCsvColumnIsARegistryEntryOrAnIdentityColumn) {
  std::set<std::string> known(runsCsvIdentityColumns().begin(), runsCsvIdentityColumns().end());
  for (const RunMetric& m : runMetrics()) known.insert(m.name);
  LineReference line(1.0, 3.0, 0.0);
  const std::vector<RunRow> rows = runMonteCarlo(shortLine("kanayama+atsmc"), line, shortSpec(), 2, 1);
  for (bool realism : {false, true}) {
    std::vector<RunRow> all = rows;
    if (realism) all.push_back(fullRow());
    const std::vector<std::string> header = splitCsv(lines(runsCsvHeader(realism)).at(0));
    std::set<std::string> seen;
    for (const std::string& column : header) {
      EXPECT_TRUE(known.count(column)) << "runs.csv column " << column << " has no entry in runMetrics()";
      EXPECT_TRUE(seen.insert(column).second) << column << " twice";
    }
    for (const RunMetric& m : runMetrics())
      EXPECT_EQ(seen.count(m.name), m.group == MetricGroup::always || realism ? 1u : 0u) << m.name;
    for (const std::string& row : lines(runsCsvLines("s", "c", all, realism)))
      EXPECT_EQ(splitCsv(row).size(), header.size()) << row;
  }
}

// The farm's packed row carries every field: unpacking gives the same CSV line, peaks, flags and series.
TEST(RunMetrics, APackedRowUnpacksToTheSameRow) {
  for (bool realism : {false, true}) {
    RunRow r = fullRow();
    r.realism = realism;
    const RunRow back = unpackRow(packRow(r));
    EXPECT_EQ(runsCsvLines("s", "c", {back}, true), runsCsvLines("s", "c", {r}, true));
    EXPECT_EQ(back.realism, realism);
    EXPECT_EQ(back.failure, r.failure);
    EXPECT_EQ(back.cross_track_series, r.cross_track_series);
    EXPECT_EQ(back.contacts, r.contacts);
    EXPECT_EQ(back.fixes_applied, r.fixes_applied);
    for (int a = 0; a < AXIS_COUNT; ++a) EXPECT_EQ(back.metrics[a].peak, r.metrics[a].peak) << a;
  }
  std::vector<double> packed = packRow(fullRow());
  packed.pop_back();
  EXPECT_THROW(unpackRow(packed), std::invalid_argument);
}
