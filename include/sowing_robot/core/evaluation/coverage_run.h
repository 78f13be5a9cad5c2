// A coverage plan sown in-process: the closed loop (runner.h, with a LoopConfig: the plant, the feedback and the layers
// of a profile) on the path follower over the plan's route from a start pose (coverage_follower.h), with the seed
// record (seed_recorder.h: SeedDrill on plan.rows(), the swaths' and the headland rows) kept beside it and judged as
// the seed figures judge rows (seed_metrics.h, docs/seeds.md). Used by the sow_field command, coverage_bench and
// test_coverage_run.
//
// A field is hours of simulated time at 1 kHz (the 1 ha L field: about 3 h), so nothing is kept per period: the
// time-domain figures are off (MetricsAccumulator without them), the trace adds to running sums, and the only record
// that grows is the seed record itself (one Seed per spacing of row sown).
#pragma once

#include <string>
#include <vector>

#include "sowing_robot/core/evaluation/seed_metrics.h"
#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {
namespace core {

struct CoverageRunSetup {
  /// The controller pair and its gains, the robot, the disturbance (as the field runs': sinusoidal, the plant 20 %
  /// heavier), the rate. Its start and duration are the run's own (start below; the route's time plus end_margin).
  Scenario scenario;
  /// The plant, feedback and layers (a profile: scenario_file::applyProfileTo); its tool is the seed-drop point, its
  /// tool_rows are set to the plan's rows. Without patches the traction plant runs on its base soil (dry).
  LoopConfig loop;
  FieldParams field;         ///< the follower's speeds: row_speed, turn_speed, max_accel (coverageFollowerParams)
  CoverageParams coverage;   ///< the plan's turn bounds (the follower's and the approach's), as the plan was made with
  Pose2D start;              ///< the robot's start pose (at rest) [m, m, rad]
  double end_margin = 20.0;  ///< simulated time after the route's planned end [s]
  bool keep_seeds = false;   ///< the seed record into CoverageRunReport::seed_record
  CoverageRunSetup();
};

struct CoverageRunReport {
  SeedFigures seeds;         ///< over the plan's rows (sown share, ISO 7256-1, lateral offset, depth, map error)
  double row_length = 0.0;   ///< the planned rows' length [m] (the swaths' and the headland rows')
  double sown_length = 0.0;  ///< of which sown (the seed figures' rule) [m]
  double sown_share = 0.0;   ///< sown_length / row_length
  double headland_row_length = 0.0;   ///< of row_length, the headland rows' (CoveragePlan::headland_rows) [m]
  double headland_sown_length = 0.0;  ///< of sown_length, on the headland rows [m]
  double swathShare() const;          ///< the swaths' rows' sown share (NaN without any)
  double headlandShare() const;       ///< the headland rows' sown share (NaN without any)
  double area_sown = 0.0;             ///< areaSown over the seed record, a row spacing wide [m^2]
  double route_time = 0.0;            ///< the follower's planned time from the start pose to the route's end [s]
  double sim_time = 0.0;              ///< simulated [s]
  double drive_work = 0.0;            ///< sum of the wheel torques sent x the wheels' rolling rates, positive part [J]
  double effort = 0.0;                ///< integral of tau_r^2 + tau_l^2 [N^2 m^2 s]
  double route_end_distance = 0.0;    ///< final axle position to the route's last point [m]
  bool finished = false;  ///< the follower's route ended, the axle within 0.3 m of its end, no divergence or stop
  bool diverged = false;
  NoTractionReport no_traction;
  double max_slip = 0.0;         ///< traction: largest |slip ratio|
  double unsown_distance = 0.0;  ///< hitch control: row the raised drill left unsown [m]
  int hitch_raises = 0;
  std::vector<Seed> seed_record;  ///< with keep_seeds
  /// The figures as lines of text (the sow_field command's and coverage_bench's).
  std::string summary() const;
};

/// Sows `plan` from setup.start. Throws std::invalid_argument on invalid parameters (the scenario, the loop's
/// configuration, the coverage parameters) or a plan without a route.
CoverageRunReport runCoverage(const CoveragePlan& plan, const CoverageRunSetup& setup);

}  // namespace core
}  // namespace sowing_robot
