#include "sowing_robot/core/simulation/field_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "sowing_robot/core/planning/field_path_follower.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {
namespace core {

Footprint sowingRobotFootprint() {
  return Footprint::convexHull({{-0.26, -0.19},
                                {0.36, -0.19},
                                {0.36, 0.19},
                                {-0.26, 0.19},
                                {-0.095, -0.265},
                                {0.095, -0.265},
                                {0.095, 0.265},
                                {-0.095, 0.265}});
}

FieldRunSetup::FieldRunSetup() {
  scenario.disturbance.sinusoidal = true;
  scenario.disturbance.mass_scale = scenario.disturbance.inertia_scale = 1.2;
  seeding.detour_margin = 4.0;
  field.avoidance.footprint_radius = footprint.circumscribedRadius();
  field.run_out = std::max(0.0, -tool.x());
}

FieldRunReport runField(const FieldRunSetup& setup) {
  const std::string e = setup.scenario.validate();
  if (!e.empty()) throw std::invalid_argument("Scenario: " + e);
  // The target starts where the robot does (field/approach), as the node does with plant_sim's start.
  FieldParams field = setup.field;
  if (!field.start_pose) field.start_pose = setup.scenario.start;
  const std::unique_ptr<FieldSource> source = makeFieldSource(field, setup.obstacles);
  FieldSource& reference = *source;
  ContactMonitor contacts(setup.footprint, setup.obstacles);
  SeedDrill drill(setup.seeding, rowsOf(setup.field),
                  setup.scoring_obstacles.empty() ? setup.obstacles : setup.scoring_obstacles,
                  setup.field.potential.influence_distance);
  FieldRunReport rep;
  auto trace = [&](const EstimatedSample& es) {
    const LoopSample& s = *es.loop;
    const State& x = *s.state;
    const Pose2D pose{x[X], x[Y], x[THETA]};
    contacts.update(s.t, pose);
    double sn, c;
    sn = std::sin(x[THETA]);
    c = std::cos(x[THETA]);
    const Eigen::Vector2d tool(x[X] + c * setup.tool.x() - sn * setup.tool.y(),
                               x[Y] + sn * setup.tool.x() + c * setup.tool.y());
    Eigen::Vector2d seed;
    drill.update(tool, s.reference->tool_down, seed);
    const Reference& r = *s.reference;
    if (s.t >= setup.peaks_from) {
      rep.peak_yaw_rate = std::max(rep.peak_yaw_rate, std::fabs(x[OMEGA]));
      rep.peak_lateral = std::max(rep.peak_lateral, std::fabs(x[V] * x[OMEGA]));
      rep.peak_ref_yaw_rate = std::max(rep.peak_ref_yaw_rate, std::fabs(r.omega));
      rep.peak_ref_lateral = std::max(rep.peak_ref_lateral, std::fabs(r.v * r.omega));
      if (r.v > 0.05) rep.peak_ref_curvature = std::max(rep.peak_ref_curvature, std::fabs(r.omega) / r.v);
    }
    rep.max_speed = std::max(rep.max_speed, std::fabs(x[V]));
    if (setup.on_step) setup.on_step(s.t, reference, contacts);
  };
  // The plant fed its own state; with setup.traction the wheel-soil plant, whose tool rule lowers the tool
  // on the field's rows (as plant_sim's TractionModel).
  LoopConfig plant;
  plant.traction = setup.traction;
  plant.patches = setup.patches;
  plant.tool = setup.tool;
  plant.tool_rows = rowsOf(setup.field);
  plant.seeding = setup.seeding;
  const LoopResult er = runClosedLoop(setup.scenario, plant, reference, false, trace);
  const RunResult& run = er.run;
  rep.max_slip = er.max_abs_slip;
  rep.tool_down_time = er.tool_down_time;
  rep.saturated = static_cast<long>(run.saturated_steps);
  contacts.finish();
  rep.min_clearance = contacts.minClearance();
  rep.contacts = contacts.contactCount();
  rep.events = contacts.events();
  rep.rows = drill.onRows();
  rep.detours = drill.detours();
  rep.end = Eigen::Vector2d(run.final_state[X], run.final_state[Y]);
  rep.status = reference.status();
  rep.diverged = run.diverged;
  return rep;
}

double approachExtraTime(const FieldRunSetup& setup) {
  FieldParams field = setup.field;
  if (!field.start_pose) field.start_pose = setup.scenario.start;
  return approachExtraTime(*makeFieldSource(field, setup.obstacles));
}

double approachExtraTime(const FieldSource& reference) {
  // The path follower drives the same field in its own time (slower on the turns): the run grows by that too.
  FieldParams without = reference.params();
  without.approach = false;
  return reference.duration() - FieldPath(without, reference.obstacles()).duration();
}

std::string FieldRunReport::summary() const {
  char b[600];
  std::snprintf(b, sizeof(b),
                "body clearance %.3f m, contacts %zu, peak yaw rate %.2f rad/s, peak lateral acceleration %.2f m/s^2 "
                "(reference: %.2f rad/s, %.2f m/s^2, curvature %.2f 1/m), max speed %.2f m/s, seeds on rows %zu "
                "(max %.1f mm, RMS %.1f mm), on detours %zu (max %.3f m), end (%.2f, %.2f), status %s%s%s%s%s",
                min_clearance, contacts, peak_yaw_rate, peak_lateral, peak_ref_yaw_rate, peak_ref_lateral,
                peak_ref_curvature, max_speed, rows.count, 1e3 * rows.max, 1e3 * rows.rms, detours.count, detours.max,
                end.x(), end.y(), AvoidanceStatus::name(status.code), status.reason.empty() ? "" : ": ",
                status.reason.c_str(), status.within_bounds ? "" : "; bounds not held: ", status.bounds_note.c_str());
  return b;
}

}  // namespace core
}  // namespace sowing_robot
