// fleet_bench: a fleet sharing one field (fleet_split.h, docs/coverage.md#fleet). Figures only, never a pass/fail.
//   fleet_bench [FIELD_FILE] [ROBOTS...]   (default config/fields/l_field.geojson, robots 1 and 3)
// The field's coverage plan (drill and turns of config/field.yaml: one row per pass, row_spacing 1 m,
// min_turn_radius 0.5 m, max_curvature_rate 10 1/m^2; two headland passes; heading auto) split among the robots,
// timed by the path follower with the field's default speeds (fieldFollowerParams: row_speed 1 m/s, turn_speed
// 0.5 m/s, max_accel 0.5 m/s^2), kept apart with FleetParams' defaults; the robots start side by side 5 m apart,
// 5 m south of the field's south-west corner, facing north. Prints per robot the planned driving time, wait,
// area rate and energy, and for the fleet the makespan, the area rate against one robot's, the closest two
// robots come and the waits.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/field_path_follower.h"
#include "sowing_robot/core/planning/fleet_split.h"
#include "sowing_robot/field_file/field_file.h"

using namespace sowing_robot::core;

int main(int argc, char** argv) {
  std::string path = std::string(SOWING_SOURCE_DIR) + "/config/fields/l_field.geojson";
  std::vector<int> counts;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::printf("usage: fleet_bench [FIELD_FILE] [ROBOTS...]   (default %s, robots 1 3)\n", path.c_str());
      return 0;
    }
    char* end = nullptr;
    const long n = std::strtol(a.c_str(), &end, 10);
    if (end && *end == '\0' && n > 0)
      counts.push_back(static_cast<int>(n));
    else
      path = a;
  }
  if (counts.empty()) counts = {1, 3};
  try {
    const FieldBoundary field = sowing_robot::field_file::loadFieldBoundary(path);
    const CoverageParams cp;  // the table's defaults: config/field.yaml's drill and turns, heading auto
    const CoveragePlan plan = planCoverage(field, cp);
    double min_x = 1e18, min_y = 1e18;
    for (const Eigen::Vector2d& p : field.outer) {
      min_x = std::min(min_x, p.x());
      min_y = std::min(min_y, p.y());
    }
    const PathParams follower = fieldFollowerParams(FieldParams());
    const FleetParams fp;
    const DriveEnergyParams energy;
    std::printf("%s: %zu swaths, %zu headland loops, route %.0f m; safety distance %.1f m, headland stretch %.0f m\n",
                path.c_str(), plan.swaths.size(), plan.headland_rings.size(), plan.path_length, fp.safety_distance,
                fp.stretch_length);
    double one_rate = 0.0;
    {
      // For reference: one robot on the planner's own route (coverageFrom: the loops in the planner's order).
      const Pose2D start{min_x + 5.0, min_y - 5.0, M_PI / 2};
      const CoveragePath route = coverageFrom(plan, start, cp);
      const PathPlan timed(route.points, PathStart{start, 0.0}, follower, route.tool_down);
      std::printf("one robot on coverageFrom's route: %.0f m, %.1f min\n", timed.length(), timed.duration() / 60.0);
    }
    for (const int n : counts) {
      std::vector<Pose2D> starts;
      for (int i = 0; i < n; ++i) starts.push_back({min_x + 5.0 + 5.0 * i, min_y - 5.0, M_PI / 2});
      const auto t0 = std::chrono::steady_clock::now();
      FleetPlan fleet = splitCoverage(plan, n, starts, cp, follower);
      const auto t1 = std::chrono::steady_clock::now();
      keepApart(fleet, plan, fp);
      const auto t2 = std::chrono::steady_clock::now();
      const FleetFigures f = fleetFigures(fleet, plan.working_width, energy);
      if (n == 1) one_rate = f.area_rate;
      std::printf("%d robot(s): split %.0f ms, keep-apart %.0f ms\n", n,
                  std::chrono::duration<double, std::milli>(t1 - t0).count(),
                  std::chrono::duration<double, std::milli>(t2 - t1).count());
      for (std::size_t i = 0; i < fleet.shares.size(); ++i) {
        const RobotShare& s = fleet.shares[i];
        const RobotFigures& r = f.robots[i];
        std::printf(
            "  robot %d (rank %d): swaths %d-%d, loops %zu, path %.0f m, planned %.1f min (estimate %.1f), wait %.0f "
            "s, "
            "%.3f ha at %.3f ha/h, %.1f Wh (%.0f Wh/ha)\n",
            s.robot, s.rank, s.first_swath, s.first_swath + s.swaths - 1, s.loops.size(), s.timed.length(),
            s.timed.duration() / 60.0, s.estimate / 60.0, s.wait, r.area / 1e4, r.area_rate, r.energy, r.energy_per_ha);
      }
      std::printf("  makespan %.1f min, %.3f ha at %.3f ha/h (%.2fx one robot), %.0f Wh/ha\n", f.makespan / 60.0,
                  f.area / 1e4, f.area_rate, one_rate > 0.0 ? f.area_rate / one_rate : 0.0, f.energy_per_ha);
      if (n > 1)
        std::printf("  waits added %d, conflict-free %s, min separation %.2f m (ranks %d, %d at %.0f s)\n",
                    fleet.waits_added, fleet.conflict_free ? "yes" : "NO", fleet.check.min_separation,
                    fleet.check.min_a, fleet.check.min_b, fleet.check.min_separation_time);
      for (const FleetWait& w : fleet.waits)
        std::printf("    wait: rank %d waits %.0f s more for rank %d (%s, %.2f m at %.1f s)\n", w.share, w.added,
                    w.conflict.a == w.share ? w.conflict.b : w.conflict.a,
                    w.conflict.headland ? "same headland stretch" : "closer than the safety distance",
                    w.conflict.distance, w.conflict.time);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fleet_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
