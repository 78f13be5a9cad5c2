// coverage_bench: the coverage planner's time and figures (docs/coverage.md). Figures only, never a pass/fail.
//   coverage_bench [runs]    (default 20: the median planning time of that many plans per field)
// Fields: the L-shaped hectare of test_coverage_planner (140 x 50 m and 60 x 50 m, a pond and a tree), and a
// 10 ha field (a pentagon of about 430 x 260 m with a pond, a copse and two poles). Drill and turns of
// config/field.yaml: one row per pass, row_spacing 1 m, min_turn_radius 0.5 m, max_curvature_rate 10 1/m^2; two
// headland passes; heading auto.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "sowing_robot/core/planning/coverage_metrics.h"
#include "sowing_robot/core/planning/coverage_planner.h"

using namespace sowing_robot::core;

namespace {

FieldBoundary lShapedHectare() {
  FieldBoundary f;
  f.outer = {{0, 0}, {140, 0}, {140, 50}, {60, 50}, {60, 100}, {0, 100}};
  f.voids = {{{20, 20}, {35, 18}, {38, 32}, {22, 35}}};
  f.circles = {Obstacle{100.0, 25.0, 3.0}};
  return f;
}

FieldBoundary tenHectares() {
  FieldBoundary f;
  f.outer = {{0, 0}, {400, -25}, {430, 200}, {190, 262}, {-15, 230}};
  f.voids = {{{120, 60}, {170, 55}, {185, 95}, {140, 120}, {110, 95}},  // a pond
             {{300, 150}, {330, 140}, {345, 170}, {310, 180}}};         // a copse
  f.circles = {Obstacle{250.0, 60.0, 1.0}, Obstacle{60.0, 180.0, 1.5}};
  return f;
}

void run(const char* name, const FieldBoundary& field, const CoverageParams& params, int runs) {
  std::vector<double> ms;
  CoveragePlan plan;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    plan = planCoverage(field, params);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  const CoverageFigures f = coverageFigures(field, plan);
  std::printf("%s: field %.0f m^2 (workable %.0f, inner %.0f), planning median %.1f ms (min %.1f, %d runs)\n", name,
              f.field_area, f.workable_area, f.inner_area, ms[ms.size() / 2], ms.front(), runs);
  std::printf("  heading %.3f rad, %d swaths in %d parts, pattern %s, %zu headland loops\n", plan.heading, f.swaths,
              plan.parts, plan.pattern == RoutePattern::kSkip ? "skip" : "boustrophedon", plan.headland_rings.size());
  std::printf(
      "  covered %.2f %% of the inner field by the swaths, %.2f %% of the workable field in all; overlap "
      "%.2f %%, missed %.2f %%, sown outside %.2f %%\n",
      100.0 * f.covered_inner_share, 100.0 * f.covered_share, 100.0 * f.overlap_share, 100.0 * f.missed_share,
      100.0 * f.outside_share);
  std::printf(
      "  path %.0f m, of it turns (tool up) %.0f m; peak curvature %.3f 1/m (bound %.3f), peak dkappa/ds "
      "%.2f 1/m^2 (bound %.2f), straight joins %d\n",
      f.path_length, f.turn_length, plan.peak_curvature, 1.0 / params.min_turn_radius, plan.peak_curvature_rate,
      params.max_curvature_rate, plan.straight_joins);
}

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 20;
  CoverageParams p;
  p.rows_per_pass = 1;
  p.row_spacing = 1.0;
  p.headland_passes = 2;
  p.min_turn_radius = 0.5;
  p.max_curvature_rate = 10.0;
  p.heading = "auto";
  try {
    run("L-shaped 1 ha, two voids", lShapedHectare(), p, runs);
    run("10 ha, four voids", tenHectares(), p, std::max(1, runs / 4));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "coverage_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
