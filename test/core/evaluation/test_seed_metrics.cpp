// Seed figures: sown share on the row's geometry, ISO 7256-1 indices, lateral offset, depth band, map error,
// each against seed records whose answer is known by construction.
#include <gtest/gtest.h>

#include <cmath>

#include "sowing_robot/core/evaluation/seed_metrics.h"
#include "sowing_robot/core/simulation/seed_recorder.h"

using namespace sowing_robot::core;

namespace {

SeedingParams params() {
  SeedingParams p;
  p.spacing = 0.1;
  p.detour_margin = 0.5;
  p.depth_min = 0.03;
  p.depth_max = 0.05;
  return p;
}

/// A 10 m row along x at y = 3 (and an optional obstacle).
SeedDrill plan(std::vector<Obstacle> obstacles = {}) {
  return SeedDrill(params(), {{Eigen::Vector2d(0, 3), Eigen::Vector2d(10, 3)}}, std::move(obstacles), 0.5);
}

/// Seeds at x = from + k step < to on the row (lateral offset dy, depth 4 cm, map error 0).
void sow(std::vector<Seed>& seeds, const SeedDrill& drill, double from, double to, double step, double dy = 0.0) {
  for (int k = 0; from + k * step < to - 1e-9; ++k) {
    const double x = from + k * step;
    Seed s;
    s.truth = s.believed = Eigen::Vector2d(x, 3.0 + dy);
    s.row = drill.nearestRow(s.truth);
    s.depth = 0.04;
    s.detour = drill.inDetour(s.truth);
    seeds.push_back(s);
  }
}

}  // namespace

TEST(SeedMetrics, ARowSownEndToEndIsAllButHalfASpacingAtEachEnd) {
  const SeedDrill d = plan();
  std::vector<Seed> seeds;
  sow(seeds, d, 0.1, 10.0, 0.1);  // 0.1 .. 9.9: the drill's first seed falls a spacing after lowering
  const SeedFigures f = seedFigures(seeds, d);
  EXPECT_EQ(f.seeds, 99u);
  ASSERT_EQ(f.rows.size(), 1u);
  // Sown [0.05, 9.95]: 9.9 of 10 m.
  EXPECT_NEAR(f.sown_share, 0.99, 1e-9);
  EXPECT_NEAR(f.worst_row_share, 0.99, 1e-9);
  EXPECT_NEAR(f.quality_of_feed, 100.0, 1e-9);
  EXPECT_NEAR(f.multiples, 0.0, 1e-12);
  EXPECT_NEAR(f.misses, 0.0, 1e-12);
  EXPECT_LT(f.precision, 1e-6);  // every spacing the same (to rounding)
  EXPECT_NEAR(f.lateral_max, 0.0, 1e-12);
  EXPECT_EQ(f.depth_outside, 0.0);
  EXPECT_EQ(f.map_error_rms, 0.0);
  EXPECT_TRUE(std::isnan(f.detour_sown_share));  // no obstacle
}

TEST(SeedMetrics, AGapOverOneAndAHalfSpacingsIsUnsownAndOneMiss) {
  const SeedDrill d = plan();
  std::vector<Seed> seeds;
  sow(seeds, d, 0.1, 4.05, 0.1);  // 0.1 .. 4.0
  sow(seeds, d, 7.0, 10.0, 0.1);  // 7.0 .. 9.9: a 3 m gap
  const SeedFigures f = seedFigures(seeds, d);
  // Sown [0.05, 4.05] and [6.95, 9.95]: 7 of 10 m.
  EXPECT_NEAR(f.sown_share, 0.70, 1e-9);
  // 40 + 30 seeds: 69 spacings, one of them the 3 m gap: M = 1/69.
  EXPECT_NEAR(f.misses, 100.0 / 69.0, 1e-9);
  EXPECT_NEAR(f.quality_of_feed, 100.0 - 100.0 / 69.0, 1e-9);
}

TEST(SeedMetrics, AGapOfOneAndAHalfSpacingsStillCountsAsSown) {
  const SeedDrill d = plan();
  std::vector<Seed> seeds;
  sow(seeds, d, 0.1, 5.05, 0.1);    // ... 5.0
  sow(seeds, d, 5.149, 10.0, 0.1);  // 5.149 ...: a spacing of 0.149, just under 1.5 x
  SeedFigures f = seedFigures(seeds, d);
  EXPECT_NEAR(f.sown_share, 0.9949, 1e-9);  // sown [0.05, 9.999]: the last seed at 9.949
  EXPECT_NEAR(f.misses, 0.0, 1e-12);
  seeds.clear();
  sow(seeds, d, 0.1, 5.05, 0.1);
  sow(seeds, d, 5.151, 10.0, 0.1);  // 0.151: over 1.5 x, a miss, and the stretch between is unsown
  f = seedFigures(seeds, d);
  EXPECT_NEAR(f.misses, 100.0 / 98.0, 1e-9);
  EXPECT_NEAR(f.sown_share, 0.9899, 1e-9);  // [0.05, 5.05] and [5.101, 10]
}

TEST(SeedMetrics, DoublesAreMultiplesAndSpreadIsPrecision) {
  const SeedDrill d = plan();
  std::vector<Seed> seeds;
  sow(seeds, d, 0.1, 10.0, 0.1);
  Seed twin = seeds[10];
  twin.truth.x() += 0.01;  // a double drop 1 cm behind
  twin.believed = twin.truth;
  seeds.push_back(twin);
  SeedFigures f = seedFigures(seeds, d);
  // 100 seeds, 99 spacings: one of 0.01 (multiple); the next 0.09 (accepted).
  EXPECT_NEAR(f.multiples, 100.0 / 99.0, 1e-9);
  EXPECT_GT(f.precision, 0.0);
  // Alternating 0.08 / 0.12 spacings: every one accepted, precision = their std / x_ref = 20 %.
  std::vector<Seed> jitter;
  for (int k = 0; k < 50; ++k) {
    sow(jitter, d, 0.1 + 0.2 * k, 0.1 + 0.2 * k + 0.01, 1.0);
    sow(jitter, d, 0.18 + 0.2 * k, 0.18 + 0.2 * k + 0.01, 1.0);
  }
  f = seedFigures(jitter, d);
  EXPECT_NEAR(f.quality_of_feed, 100.0, 1e-9);
  EXPECT_NEAR(f.precision, 20.0, 0.3);  // sample std of alternating +-0.02 around 0.1
}

TEST(SeedMetrics, ObstacleStretchesAreWhereTheRowIsBlocked) {
  // An obstacle of 0.3 m on the row at x = 5 blocks it within 0.3 + 0.5 (influence) = 0.8 m: [4.2, 5.8]. The
  // robot leaves the row before it and rejoins after: the seeds it places there, 0.3 m off the line, sow the row.
  const SeedDrill d = plan({{5.0, 3.0, 0.3}});
  std::vector<Seed> seeds;
  sow(seeds, d, 0.1, 3.65, 0.1);       // on the line up to 3.6
  sow(seeds, d, 3.7, 4.15, 0.1, 0.3);  // leaving it: 3.7 .. 4.1
  sow(seeds, d, 5.9, 6.35, 0.1, 0.3);  // rejoining: 5.9 .. 6.3
  sow(seeds, d, 6.4, 10.0, 0.1);       // on the line again
  SeedFigures f = seedFigures(seeds, d);
  ASSERT_EQ(f.rows.size(), 1u);
  EXPECT_NEAR(f.rows[0].detour_length, 1.6, 1e-9);
  EXPECT_NEAR(f.rows[0].length, 8.4, 1e-9);
  // Sown [0.05, 4.15] and [5.85, 9.95]: 4.1 + 4.1 = 8.2 of 8.4; nothing of the blocked stretch.
  EXPECT_NEAR(f.sown_share, 8.2 / 8.4, 1e-9);
  EXPECT_NEAR(f.detour_sown_share, 0.0, 1e-9);
  // The gap across the blocked stretch is not an ISO miss (its seeds border the obstacle, not a fault).
  EXPECT_NEAR(f.misses, 0.0, 1e-12);

  // A drill lifted for the whole detour leaves the row unsown where it could have been sown: counted.
  seeds.clear();
  sow(seeds, d, 0.1, 3.65, 0.1);
  sow(seeds, d, 6.4, 10.0, 0.1);
  f = seedFigures(seeds, d);
  EXPECT_NEAR(f.sown_share, 7.2 / 8.4, 1e-9);
}

TEST(SeedMetrics, LateralDepthAndMapError) {
  const SeedDrill d = plan();
  std::vector<Seed> seeds;
  sow(seeds, d, 0.1, 5.05, 0.1, 0.02);                         // 50 seeds 2 cm left
  sow(seeds, d, 5.1, 10.0, 0.1, -0.04);                        // 49 seeds 4 cm right
  for (std::size_t i = 0; i < 10; ++i) seeds[i].depth = 0.02;  // 10 too shallow
  for (Seed& s : seeds) s.believed = s.truth + Eigen::Vector2d(0.03, 0.0);
  const SeedFigures f = seedFigures(seeds, d);
  EXPECT_NEAR(f.lateral_max, 0.04, 1e-9);
  EXPECT_NEAR(f.lateral_p95, 0.04, 1e-9);
  EXPECT_NEAR(f.lateral_rms, std::sqrt((50 * 0.0004 + 49 * 0.0016) / 99.0), 1e-9);
  EXPECT_NEAR(f.depth_outside, 10.0 / 99.0, 1e-12);
  EXPECT_NEAR(f.map_error_rms, 0.03, 1e-9);
  EXPECT_NEAR(f.map_error_p95, 0.03, 1e-9);
}

TEST(SeedMetrics, NoSeedsMeansNothingSownAndNoIndices) {
  const SeedDrill d = plan();
  const SeedFigures f = seedFigures({}, d);
  EXPECT_EQ(f.sown_share, 0.0);
  EXPECT_EQ(f.worst_row_share, 0.0);
  EXPECT_TRUE(std::isnan(f.quality_of_feed));
  EXPECT_TRUE(std::isnan(f.lateral_rms));
  EXPECT_TRUE(std::isnan(f.map_error_rms));
}

TEST(SeedMetrics, SeedsFromTheDrillItselfSowTheRow) {
  // The drill's own rule on a tool point driven along the row at 1 mm steps: the record is what the drill drops.
  SeedDrill d = plan();
  std::vector<Seed> seeds;
  Seed s;
  for (int i = 0; i <= 10050; ++i) {  // from 0.5 mm to 10.0505 m, clear of rounding at the row's ends
    const Eigen::Vector2d p(i * 1e-3 + 5e-4, 3.0);
    if (d.drop(i * 1e-3, p, p, true, false, 0.04, s)) seeds.push_back(s);
  }
  const SeedFigures f = seedFigures(seeds, d);
  // Every 0.1 m from 0.1005 to 9.9005; the 100th would fall 0.5 mm past the row's end, where the drill is lifted
  // (a seed falls only on a row's stretch, whatever the plan asks).
  EXPECT_EQ(f.seeds, 99u);
  EXPECT_NEAR(f.sown_share, 0.99, 1e-9);  // [0.0505, 9.9505]
  EXPECT_NEAR(f.quality_of_feed, 100.0, 1e-9);
  EXPECT_EQ(seeds.front().row, 0);
  EXPECT_DOUBLE_EQ(seeds.back().t + 5e-4, seeds.back().truth.x());
}

TEST(SeedMetrics, UnsownLengthIsLocatedAtTheRowsStartEndAndBetweenSeeds) {
  const SeedDrill d = plan();
  std::vector<Seed> seeds;
  sow(seeds, d, 1.0, 4.05, 0.1);  // 1.0 .. 4.0
  sow(seeds, d, 7.0, 9.05, 0.1);  // 7.0 .. 9.0
  const SeedFigures f = seedFigures(seeds, d);
  // Sown [0.95, 4.05] and [6.95, 9.05].
  EXPECT_NEAR(f.unsown_start, 0.95, 1e-9);
  EXPECT_NEAR(f.unsown_end, 0.95, 1e-9);
  EXPECT_NEAR(f.unsown_mid, 2.9, 1e-9);
  EXPECT_NEAR(f.rows[0].unsown_start, 0.95, 1e-9);
  EXPECT_NEAR(f.rows[0].unsown_end, 0.95, 1e-9);
  EXPECT_TRUE(std::isnan(f.unsown_held_up));  // no passes: the causes are not known
  EXPECT_TRUE(std::isnan(f.unsown_not_engaged));
  EXPECT_TRUE(std::isnan(f.unsown_not_asked));
  // A row without a seed is unsown at its start, all of it.
  EXPECT_NEAR(seedFigures({}, d).unsown_start, 10.0, 1e-9);
}

TEST(SeedMetrics, UnsownLengthIsPutDownToTheDrillsStateWhereTheToolPointPassed) {
  const SeedDrill d = plan();
  std::vector<Seed> seeds;
  sow(seeds, d, 1.0, 4.05, 0.1);
  sow(seeds, d, 7.0, 9.05, 0.1);
  const std::vector<RowPass> passes{{0, DrillState::not_asked, 0.0, 0.5},    {0, DrillState::not_engaged, 0.5, 0.95},
                                    {0, DrillState::down, 0.95, 4.05},       {0, DrillState::held_up, 4.05, 6.0},
                                    {0, DrillState::not_engaged, 6.0, 6.95}, {0, DrillState::down, 6.95, 9.5}};
  const SeedFigures f = seedFigures(seeds, d, &passes);
  EXPECT_NEAR(f.unsown_held_up, 1.95, 1e-9);
  EXPECT_NEAR(f.unsown_not_engaged, 0.45 + 0.95, 1e-9);
  EXPECT_NEAR(f.unsown_not_asked, 0.5, 1e-9);
  // The rest: passed with the drill down [9.05, 9.5] and never passed [9.5, 10].
  EXPECT_NEAR(
      f.unsown_start + f.unsown_end + f.unsown_mid - f.unsown_held_up - f.unsown_not_engaged - f.unsown_not_asked, 0.95,
      1e-9);
  // The hitch comes first where passes of several states overlap.
  const std::vector<RowPass> both{{0, DrillState::not_engaged, 4.0, 7.0}, {0, DrillState::held_up, 4.05, 6.0}};
  const SeedFigures g = seedFigures(seeds, d, &both);
  EXPECT_NEAR(g.unsown_held_up, 1.95, 1e-9);
  EXPECT_NEAR(g.unsown_not_engaged, 0.95, 1e-9);
}

TEST(SeedMetrics, TheRecordersPassesShowTheDrillWaitingForTheRowsLine) {
  // The tool point (the robot's, with the tool at its axle) 2 cm beside the row until x = 2, then on its line; the
  // plan asks for the drill from x = 0.5. The drill is lowered only at x = 2 (engage_distance 1 cm).
  SeedRecorder record(plan(), Eigen::Vector2d::Zero());
  State x = State::Zero();
  Reference ref;
  for (int i = -1000; i <= 11000; ++i) {
    x[X] = i * 1e-3 + 5e-4;
    x[Y] = x[X] < 2.0 ? 3.02 : 3.0;
    ref.tool_down = x[X] >= 0.5;
    record.add(LoopSample{i * 1e-3, &x, &ref, nullptr, nullptr, 0.0, 0.0, 0.0, 0.0, 0.0});
  }
  const SeedFigures f = seedFigures(record.seeds(), record.drill(), &record.passes());
  // The first seed a spacing after the drill is lowered, less the tool point's 2 cm step onto the line (travel).
  EXPECT_NEAR(f.unsown_start, 2.03, 2e-3);
  EXPECT_NEAR(f.unsown_not_asked, 0.5, 2e-3);
  EXPECT_NEAR(f.unsown_not_engaged, 1.5, 2e-3);
  EXPECT_NEAR(f.unsown_held_up, 0.0, 1e-12);
  EXPECT_NEAR(f.unsown_mid, 0.0, 1e-9);
}
