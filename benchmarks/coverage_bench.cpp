// coverage_bench: the coverage planner's time and figures, and the L field sown in-process (docs/coverage.md).
// Figures only, never a pass/fail.
//   coverage_bench [runs] [--no-sow]   (runs, default 20: the median planning time of that many plans per field)
// Fields: config/fields/l_field.geojson (the 1 ha L-shaped field with a pond and a power pole, field_file.md), and a
// 10 ha field (a pentagon of about 430 x 260 m with a pond, a copse and two poles). Drill and turns of
// config/field.yaml: one row per pass, row_spacing 1 m, min_turn_radius 0.5 m, max_curvature_rate 10 1/m^2; two
// headland passes; heading auto; each swath driven on by the tool's 0.45 m (coverage/run_out).
// Then the L field sown in-process on one core (core/evaluation/coverage_run.h) with the recommended set-up: the
// field profile (config/profiles/field.yaml: traction plant on dry soil, motors, layers, fused feedback), rpp+pid with
// its gains (config/tuned/field/rpp+pid.yaml), from 1 m before the first swath: the wall time (target <= 60 s), the
// simulated time, the planned row length (the swaths' and the headland rows), the sown share of each (target >= 98 %)
// and the area sown against the plan's covered area; and where the wall time
// goes (the same route with the profile's layers and then its fused feedback taken out).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <stdexcept>
#include <string>
#include <vector>

#include "sowing_robot/core/evaluation/coverage_run.h"
#include "sowing_robot/core/planning/coverage_metrics.h"
#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/field_file/field_file.h"
#include "sowing_robot/scenario_file/scenario_loader.h"

using namespace sowing_robot::core;

namespace {

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
      "  covered %.2f %% of the inner field by the swaths, %.2f %% of the workable field in all (%.0f m^2); overlap "
      "%.2f %%, missed %.2f %%, sown outside %.2f %%\n",
      100.0 * f.covered_inner_share, 100.0 * f.covered_share, f.covered_area, 100.0 * f.overlap_share,
      100.0 * f.missed_share, 100.0 * f.outside_share);
  double swath_rows = 0.0, headland_rows = 0.0;
  for (const Swath& s : plan.swaths)
    for (const RowSegment& r : s.rows) swath_rows += (r.b - r.a).norm();
  for (const RowSegment& r : plan.headland_rows) headland_rows += (r.b - r.a).norm();
  std::printf("  rows %.0f m: the swaths' %.0f m, %zu headland rows %.0f m; the rows' area %.0f m^2\n",
              swath_rows + headland_rows, swath_rows, plan.headland_rows.size(), headland_rows, f.row_area);
  std::printf(
      "  path %.0f m, of it turns (tool up) %.0f m; peak curvature %.3f 1/m (bound %.3f), peak dkappa/ds "
      "%.2f 1/m^2 (bound %.2f), straight joins %d\n",
      f.path_length, f.turn_length, plan.peak_curvature, 1.0 / params.min_turn_radius, plan.peak_curvature_rate,
      params.max_curvature_rate, plan.straight_joins);
}

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// 1 m before the plan's first swath, facing along it.
Pose2D beforeFirstSwath(const CoveragePlan& plan) {
  const Swath& first = plan.swaths.front();
  const Eigen::Vector2d along = (first.b - first.a).normalized(), behind = first.a - along;
  return {behind.x(), behind.y(), std::atan2(along.y(), along.x())};
}

/// One sowing of `plan`: its figures, its wall time and the process's CPU time over it [s] (the machine is shared:
/// CPU time is the steadier figure under load).
CoverageRunReport sow(const CoveragePlan& plan, CoverageRunSetup setup, double& wall, double& cpu) {
  setup.start = beforeFirstSwath(plan);
  const auto t0 = Clock::now();
  const std::clock_t c0 = std::clock();
  CoverageRunReport r = runCoverage(plan, setup);
  cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  wall = secondsSince(t0);
  return r;
}

/// One line of a variant of the run: its wall time per control period.
void sowVariant(const char* label, const CoveragePlan& plan, const CoverageRunSetup& setup) {
  double wall = 0.0, cpu = 0.0;
  const CoverageRunReport r = sow(plan, setup, wall, cpu);
  const double periods = r.sim_time / secondsFromNanos(setup.scenario.control_period_ns);
  std::printf("  %s: %.1f s wall, %.1f s CPU (%.2f us CPU per control period), %s, sown %.2f %%\n", label, wall, cpu,
              1e6 * cpu / periods, r.finished ? "finished" : "NOT finished", 100.0 * r.sown_share);
}

/// The L field sown with the recommended set-up, then the same without the profile's feedback, layers and traction
/// plant in turn (where the time goes).
void sowLField(const FieldBoundary& field, CoverageParams p) {
  namespace sf = sowing_robot::scenario_file;
  CoverageRunSetup setup;
  const std::string e =
      parseControllerPair("rpp+pid", setup.scenario.outer, setup.scenario.inner, setup.scenario.sliding.adaptive);
  if (!e.empty()) throw std::invalid_argument(e);
  const sf::ProfileFiles profile = sf::resolveProfile("field", SOWING_SOURCE_DIR);
  sf::applyProfileTo(profile.file, setup.loop);
  sf::applyTunedGains(sf::tunedGainsFile(profile.gains_dir, setup.scenario), setup.scenario);
  p.run_out = std::max(0.0, -setup.loop.tool.x());
  setup.coverage = p;
  const auto t0 = Clock::now();
  const CoveragePlan plan = planCoverage(field, p);
  std::printf("L field sown in-process, one core (plan %.0f ms, path %.0f m, %zu swaths, %zu headland rows):\n",
              1e3 * secondsSince(t0), plan.path_length, plan.swaths.size(), plan.headland_rows.size());
  const CoverageFigures f = coverageFigures(field, plan);
  double wall = 0.0, cpu = 0.0;
  const CoverageRunReport r = sow(plan, setup, wall, cpu);
  const double periods = r.sim_time / secondsFromNanos(setup.scenario.control_period_ns);
  std::printf(
      "  field profile, rpp+pid, dry soil: wall %.1f s (target <= 60 s), CPU %.1f s (%.2f us per control "
      "period)\n%s\n",
      wall, cpu, 1e6 * cpu / periods, r.summary().c_str());
  std::printf("  area sown %.0f m^2 = %.2f %% of the plan's covered %.0f m^2 (%.2f %% of its rows' %.0f m^2)\n",
              r.area_sown, 100.0 * r.area_sown / f.covered_area, f.covered_area, 100.0 * r.area_sown / f.row_area,
              f.row_area);
  std::fflush(stdout);
  // Where the time goes: the same route and pair fed the truth (no EKF), then without motors and layers, then on the
  // no-slip plant.
  CoverageRunSetup variant = setup;
  variant.loop.feedback = Feedback::ground_truth;
  sowVariant("the same fed the truth (no EKF)", plan, variant);
  variant.loop = LoopConfig();
  variant.loop.traction = setup.loop.traction;
  sowVariant("fed the truth, traction plant without motors or layers", plan, variant);
  variant.loop.traction.reset();
  sowVariant("fed the truth, the no-slip plant", plan, variant);
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 20;
  bool sow_field = true;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--no-sow")
      sow_field = false;
    else
      runs = std::max(1, std::atoi(argv[i]));
  }
  CoverageParams p;  // the table's defaults: config/field.yaml's drill and turns, heading auto
  p.run_out = 0.45;  // the URDF's tool_link: 0.45 m behind the axle
  try {
    const FieldBoundary l_field =
        sowing_robot::field_file::loadFieldBoundary(std::string(SOWING_SOURCE_DIR) + "/config/fields/l_field.geojson");
    run("L-shaped 1 ha, two voids (config/fields/l_field.geojson)", l_field, p, runs);
    run("10 ha, four voids", tenHectares(), p, std::max(1, runs / 4));
    if (sow_field) sowLField(l_field, p);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "coverage_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
