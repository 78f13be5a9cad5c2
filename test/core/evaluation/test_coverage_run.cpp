// A small planned field sown in-process (coverage_run.h): a 20 m x 30 m field with a void in its middle, one row per
// pass 1 m apart, two headland passes, each swath driven on by the tool's 0.45 m. On dry soil (the traction plant on
// its base soil) with rpp+pid fed the truth, the rows (the swaths' and the headland loops' straight sides) are sown end
// to end, the seeds lie on the rows (none in the headland loops' corners), and the run ends at the route's end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sowing_robot/core/evaluation/coverage_run.h"
#include "sowing_robot/core/planning/coverage_metrics.h"
#include "sowing_robot/scenario_file/scenario_loader.h"

using namespace sowing_robot::core;

namespace {

FieldBoundary smallField() {
  FieldBoundary f;
  f.outer = {{0, 0}, {20, 0}, {20, 30}, {0, 30}};
  f.voids = {{{9, 14}, {11, 14}, {11, 16}, {9, 16}}};
  return f;
}

CoverageRunSetup drySetup() {
  CoverageRunSetup s;
  const std::string e = parseControllerPair("rpp+pid", s.scenario.outer, s.scenario.inner, s.scenario.sliding.adaptive);
  EXPECT_EQ(e, "");
  namespace sf = sowing_robot::scenario_file;
  const sf::ProfileFiles profile = sf::resolveProfile("field", SOWING_SOURCE_DIR);
  sf::applyProfileTo(profile.file, s.loop);  // no patches: the traction plant's base soil, dry
  s.loop.feedback = Feedback::ground_truth;
  sf::applyTunedGains(sf::tunedGainsFile(profile.gains_dir, s.scenario), s.scenario);
  s.coverage.heading = "auto";
  s.coverage.run_out = -s.loop.tool.x();
  s.keep_seeds = true;
  return s;
}

Pose2D beforeFirstSwath(const CoveragePlan& plan) {
  const Swath& first = plan.swaths.front();
  const Eigen::Vector2d along = (first.b - first.a).normalized(), behind = first.a - along;
  return {behind.x(), behind.y(), std::atan2(along.y(), along.x())};
}

}  // namespace

TEST(CoverageRun, ASmallFieldWithAVoidIsSownEndToEndOnDrySoil) {
  const FieldBoundary field = smallField();
  CoverageRunSetup setup = drySetup();
  const CoveragePlan plan = planCoverage(field, setup.coverage);
  ASSERT_GE(plan.swaths.size(), 10u);
  setup.start = beforeFirstSwath(plan);
  const CoverageRunReport r = runCoverage(plan, setup);
  std::printf("%s\n", r.summary().c_str());

  // The planned rows are the swaths' rows and the headland rows, all of them judged, each kind apart.
  double planned = 0.0, headland = 0.0;
  for (const RowSegment& row : plan.rows()) planned += (row.b - row.a).norm();
  for (const RowSegment& row : plan.headland_rows) headland += (row.b - row.a).norm();
  // The outer loop's sides (20 and 30 m less the corners and the run-out) on two passes, the void's (2 m) on two.
  EXPECT_EQ(plan.headland_rows.size(), 16u);
  EXPECT_GT(headland, 150.0);
  EXPECT_NEAR(r.row_length, planned, 1e-6);
  EXPECT_NEAR(r.headland_row_length, headland, 1e-6);
  EXPECT_EQ(r.seeds.rows.size(), plan.rows().size());
  EXPECT_GE(r.sown_share, 0.98);
  EXPECT_GE(r.swathShare(), 0.98);
  // The headland rows: 95.9 % measured. The void's rings have sides of 1.45 m (2 m less the corners' rounding,
  // then less the run-out): the tool point, swinging in from the corner, is on the line within engage_distance only
  // for the last part of them (the worst row, 46 %).
  EXPECT_GE(r.headlandShare(), 0.94);
  EXPECT_GE(r.seeds.worst_row_share, 0.4);
  EXPECT_GE(r.seeds.quality_of_feed, 95.0);
  EXPECT_GT(r.area_sown, 0.9 * planned * plan.working_width);
  const CoverageFigures fig = coverageFigures(field, plan);
  EXPECT_GT(r.area_sown, 0.95 * fig.row_area);
  EXPECT_LT(r.area_sown, fig.covered_area);

  // Every seed on its row: between its ends (a seed spacing's slack) and within a few centimetres of its line; the
  // headland rows' seeds among them (the drill lowered on the loops' sides, and lifted in their corners).
  ASSERT_EQ(r.seed_record.size(), r.seeds.seeds);
  const std::vector<RowSegment> rows = plan.rows();
  std::size_t on_headland = 0;
  for (const Seed& s : r.seed_record) {
    ASSERT_GE(s.row, 0);
    if (static_cast<std::size_t>(s.row) >= plan.swathRows()) ++on_headland;
    const RowSegment& row = rows[static_cast<std::size_t>(s.row)];
    const Eigen::Vector2d u = (row.b - row.a).normalized();
    const double along_row = (s.truth - row.a).dot(u),
                 across = std::fabs(u.x() * (s.truth - row.a).y() - u.y() * (s.truth - row.a).x());
    EXPECT_GE(along_row, -0.05) << "seed at t " << s.t;
    EXPECT_LE(along_row, (row.b - row.a).norm() + 0.05) << "seed at t " << s.t;
    EXPECT_LE(across, 0.05) << "seed at t " << s.t;
  }
  EXPECT_GT(static_cast<double>(on_headland), 0.9 * headland / setup.loop.seeding.spacing);

  // The run ends at the route's end, at rest there, its route ended in time.
  EXPECT_TRUE(r.finished);
  EXPECT_LT(r.route_end_distance, 0.3);
  EXPECT_FALSE(r.diverged);
  EXPECT_GE(r.sim_time, r.route_time);
  EXPECT_GT(r.drive_work, 0.0);
}

TEST(CoverageRun, WithoutRunOutTheToolPointFallsShortOfTheRowsEnds) {
  // The same field with swaths that end where the turn begins: the tool point, 0.45 m behind the axle, leaves the
  // rows' ends unsown (about 0.2 m each: the drill stays down on the line while the turn begins), which
  // CoverageParams::run_out gives back.
  const FieldBoundary field = smallField();
  CoverageRunSetup setup = drySetup();
  double share[2];
  for (const double run_out : {0.0, 0.45}) {
    setup.coverage.run_out = run_out;
    const CoveragePlan plan = planCoverage(field, setup.coverage);
    setup.start = beforeFirstSwath(plan);
    share[run_out > 0.0] = runCoverage(plan, setup).sown_share;
  }
  EXPECT_GT(share[1], share[0] + 0.005) << "without " << share[0] << ", with " << share[1];
}

TEST(CoverageRun, RefusesAnInvalidSetUp) {
  const FieldBoundary field = smallField();
  CoverageRunSetup setup = drySetup();
  const CoveragePlan plan = planCoverage(field, setup.coverage);
  setup.scenario.control_period_ns = 0;
  EXPECT_THROW(runCoverage(plan, setup), std::invalid_argument);
  EXPECT_THROW(runCoverage(CoveragePlan(), drySetup()), std::invalid_argument);
}
