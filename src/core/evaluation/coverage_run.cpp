#include "sowing_robot/core/evaluation/coverage_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "sowing_robot/core/planning/coverage_follower.h"
#include "sowing_robot/core/planning/coverage_metrics.h"
#include "sowing_robot/core/simulation/seed_recorder.h"

namespace sowing_robot {
namespace core {

CoverageRunSetup::CoverageRunSetup() {
  // The field runs' plant (FieldRunSetup): the thesis's sinusoidal disturbance on a plant 20 % heavier than the model.
  scenario.disturbance.sinusoidal = true;
  scenario.disturbance.mass_scale = scenario.disturbance.inertia_scale = 1.2;
  loop.seeding.detour_margin = 4.0;  // as config/seed_drill.yaml
}

namespace {

/// The running sums a coverage run keeps per period (nothing stored per period).
struct Sums {
  double dt = 0.0, half_track = 0.0, radius = 0.0;
  double work = 0.0, effort = 0.0;
  void add(const EstimatedSample& s) {
    const State& x = *s.loop->state;
    const double wr = (x[V] + half_track * x[OMEGA]) / radius, wl = (x[V] - half_track * x[OMEGA]) / radius;
    work += dt * std::max(0.0, s.sent.right * wr + s.sent.left * wl);
    effort += dt * (s.sent.right * s.sent.right + s.sent.left * s.sent.left);
  }
};

}  // namespace

CoverageRunReport runCoverage(const CoveragePlan& plan, const CoverageRunSetup& setup) {
  PathReference reference = coverageReference(plan, setup.start, setup.field, setup.coverage);
  const double route_end = reference.planStart() + reference.plan().duration();
  Scenario sc = setup.scenario;
  sc.start = setup.start;
  sc.duration = route_end + setup.end_margin;
  LoopConfig cfg = setup.loop;
  const std::vector<RowSegment> rows = plan.rows();
  cfg.tool_rows = rows;
  cfg.tool_rows_open_ended = false;
  // A robot slowed for grip is judged at the same point of its route (the benchmark's field runs do the same).
  cfg.governed_time_back = true;

  SeedRecorder record(SeedDrill(cfg.seeding, rows, {}, 0.0), cfg.tool);
  Sums sums;
  sums.dt = secondsFromNanos(sc.control_period_ns);
  sums.half_track = sc.robot.L;
  sums.radius = sc.robot.R;
  double last_t = 0.0;
  const LoopResult lr = runClosedLoop(sc, cfg, reference, false, [&](const EstimatedSample& s) {
    record.add(s);
    sums.add(s);
    last_t = s.loop->t;
  });

  CoverageRunReport rep;
  rep.seeds = seedFigures(record.seeds(), record.drill());
  const std::size_t swath_rows = plan.swathRows();  // rows() holds the swaths' rows first, then the headland rows
  for (std::size_t i = 0; i < rep.seeds.rows.size(); ++i) {
    const RowSowing& r = rep.seeds.rows[i];
    rep.row_length += r.length + r.detour_length;
    rep.sown_length += r.sown + r.detour_sown;
    if (i < swath_rows) continue;
    rep.headland_row_length += r.length + r.detour_length;
    rep.headland_sown_length += r.sown + r.detour_sown;
  }
  rep.sown_share = rep.row_length > 0.0 ? rep.sown_length / rep.row_length : 0.0;
  const double row_width = plan.swaths.empty() || plan.swaths.front().rows.empty()
                               ? plan.working_width
                               : plan.working_width / static_cast<double>(plan.swaths.front().rows.size());
  rep.area_sown = areaSown(record.seeds(), row_width, cfg.seeding.spacing);
  rep.route_time = route_end;
  rep.sim_time = last_t;
  rep.drive_work = sums.work;
  rep.effort = sums.effort;
  const State& x = lr.run.final_state;
  const Eigen::Vector2d goal = reference.plan().goal();  // the route's last point, as planned before the run
  rep.route_end_distance = std::hypot(x[X] - goal.x(), x[Y] - goal.y());
  rep.diverged = lr.run.diverged;
  rep.no_traction = lr.no_traction;
  rep.finished =
      !rep.diverged && !rep.no_traction.detected && reference.lastTime() >= route_end && rep.route_end_distance < 0.3;
  rep.max_slip = lr.max_abs_slip;
  rep.unsown_distance = lr.unsown_distance;
  rep.hitch_raises = lr.hitch_raises;
  if (setup.keep_seeds) rep.seed_record = record.takeSeeds();
  return rep;
}

double CoverageRunReport::swathShare() const {
  const double length = row_length - headland_row_length;
  return length > 0.0 ? (sown_length - headland_sown_length) / length : std::nan("");
}

double CoverageRunReport::headlandShare() const {
  return headland_row_length > 0.0 ? headland_sown_length / headland_row_length : std::nan("");
}

std::string CoverageRunReport::summary() const {
  char b[1100];
  std::snprintf(b, sizeof(b),
                "rows %.1f m planned, sown %.1f m = %.2f %% (worst row %.2f %%); area sown %.1f m^2\n"
                "swaths' rows %.1f m, sown %.2f %%; headland rows %.1f m, sown %.2f %%\n"
                "seeds %zu: quality of feed %.2f %% (multiples %.2f %%, misses %.2f %%), lateral p95 %.1f mm "
                "(RMS %.1f mm), depth outside the band %.2f %%, seed-map error RMS %.1f mm\n"
                "time %.1f s simulated (route %.1f s), drive work %.1f kJ, effort %.4g N^2 m^2 s, max slip %.3f, "
                "hitch raises %d (%.2f m unsown)\n"
                "end: %s, %.3f m from the route's end%s%s",
                row_length, sown_length, 100.0 * sown_share, 100.0 * seeds.worst_row_share, area_sown,
                row_length - headland_row_length, 100.0 * swathShare(), headland_row_length, 100.0 * headlandShare(),
                seeds.seeds, seeds.quality_of_feed, seeds.multiples, seeds.misses, 1e3 * seeds.lateral_p95,
                1e3 * seeds.lateral_rms, 100.0 * seeds.depth_outside, 1e3 * seeds.map_error_rms, sim_time, route_time,
                1e-3 * drive_work, effort, max_slip, hitch_raises, unsown_distance,
                finished ? "finished" : "NOT finished", route_end_distance, diverged ? ", diverged" : "",
                no_traction.detected ? (", " + no_traction.text()).c_str() : "");
  return b;
}

}  // namespace core
}  // namespace sowing_robot
