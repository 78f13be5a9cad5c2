// Seed drill: spacing along the travelled path, tool up/down, cross-track error, detour split.
#include <gtest/gtest.h>

#include <cmath>

#include "sowing_robot/core/planning/seeding.h"

using namespace sowing_robot::core;

namespace {
SeedDrill lineDrill(std::vector<Obstacle> obstacles = {}) {
  SeedingParams p;
  p.spacing = 0.1;
  p.tolerance = 0.02;
  p.detour_margin = 0.5;
  p.engage_distance = 0.05;
  return SeedDrill(p, {{Eigen::Vector2d(0, 3), Eigen::Vector2d(100, 3)}}, std::move(obstacles), 0.5);
}
}  // namespace

TEST(Seeding, OneSeedPerSpacingOfTravelWithTheToolDown) {
  SeedDrill d = lineDrill();
  Eigen::Vector2d seed;
  int n = 0;
  for (int i = 0; i <= 10050; ++i)  // 10.05 m in 1 mm steps: 100 seeds, clear of rounding at 10 m
    n += d.update({i * 1e-3, 3.0}, true, seed);
  EXPECT_EQ(n, 100);
  EXPECT_EQ(d.onRows().count, 100u);
  EXPECT_NEAR(d.onRows().max, 0.0, 1e-12);
}

TEST(Seeding, NoSeedsWithTheToolUp) {
  SeedDrill d = lineDrill();
  Eigen::Vector2d seed;
  int n = 0;
  for (int i = 0; i <= 5000; ++i) n += d.update({i * 1e-3, 3.0}, false, seed);
  EXPECT_EQ(n, 0);
}

TEST(Seeding, TheToolIsLoweredOnlyOnceOnTheRow) {
  // Approach from 0.5 m beside the row (slope 0.1) to x = 5, then 3 m along it.
  SeedDrill d = lineDrill();
  Eigen::Vector2d seed;
  int approach = 0, along = 0;
  for (int i = 0; i <= 5000; ++i) approach += d.update({i * 1e-3, 3.5 - 0.1 * i * 1e-3}, true, seed);
  for (int i = 5001; i <= 8050; ++i) along += d.update({i * 1e-3, 3.0}, true, seed);
  // Lowered within 5 cm of the row (engage_distance set so): the last 0.5 m of the approach.
  EXPECT_EQ(approach, 5);
  EXPECT_EQ(along, 30);
  EXPECT_LE(d.onRows().max, 0.05 + 1e-9);
}

TEST(Seeding, CrossTrackErrorIsTheDistanceToTheNearestRow) {
  SeedDrill d = lineDrill();
  EXPECT_NEAR(d.crossTrack({50, 3.03}), 0.03, 1e-12);
  EXPECT_NEAR(d.crossTrack({-4, 6}), 5.0, 1e-12);  // beyond the row's start: distance to its end point
  Eigen::Vector2d seed;
  for (int i = 0; i <= 2000; ++i) d.update({i * 1e-3, 3.0 + 0.03 * std::sin(i * 1e-3)}, true, seed);
  EXPECT_GT(d.onRows().max, 0.02);
  EXPECT_GT(d.onRows().fraction_over, 0.0);
  EXPECT_LT(d.onRows().fraction_over, 1.0);
}

TEST(Seeding, SeedsNearObstaclesAreDetourSeeds) {
  SeedDrill d = lineDrill({{20, 3, 0.3}});
  Eigen::Vector2d seed;
  for (int i = 0; i <= 30000; ++i) {  // a 0.8 m wide bump around x = 20
    const double x = i * 1e-3;
    d.update({x, 3.0 + (std::fabs(x - 20) < 1.0 ? 0.8 : 0.0)}, true, seed);
  }
  EXPECT_GT(d.detours().count, 0u);
  EXPECT_NEAR(d.detours().max, 0.8, 1e-9);
  EXPECT_NEAR(d.onRows().max, 0.0, 1e-12);  // the detour does not spoil the straight-row figures
}

TEST(Seeding, RowsOfAFieldAlternateDirection) {
  FieldParams f;
  f.rows = 3;
  f.row_length = 30;
  const auto rows = rowsOf(f);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_NEAR((rows[0].b - rows[0].a).norm(), 30.0, 1e-9);
  EXPECT_LT((rows[1].b - rows[1].a).dot(rows[0].b - rows[0].a), 0.0);
}
