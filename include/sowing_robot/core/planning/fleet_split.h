// A fleet that shares one field: one coverage plan (coverage_planner.h) split among N robots, kept apart by the plan,
// and the fleet's figures (docs/coverage.md#fleet).
//
//   * Split (splitCoverage): the route's swaths cut into N blocks, each contiguous in route order (a robot drives
//     its block as the single robot would, turns included), and the headland loops handed out whole. The costs are
//     driving times through the path follower's timing (PathPlan with the field's speeds, fieldFollowerParams):
//     a swath costs the time from its start to the next swath's start on the whole route timed once (its turn
//     included), a loop its own PathPlan from rest. The loops go first, longest first to the block with the least
//     loop time (LPT), and the swath cuts then even out every robot's total (swaths + loops + approach), so a
//     robot with a long loop gets fewer swaths. Each robot's route: a tool-up approach from its start pose onto its
//     first swath (coverageJoin), its block, then its loops nearest first, each reached by a tool-up join. Which
//     robot takes which block ("reorder"): the assignment of start poses to blocks with the shortest longest
//     approach (every permutation; N <= 8).
//   * Keep apart (keepApart): every robot's timed path (PathPlan::at) sampled on one clock from the fleet's start;
//     a robot stands at its start pose while it waits and leaves the check once it has finished. A conflict: two
//     robots closer than safety_distance, or two driving robots in the same headland stretch (the band between
//     the field boundary and the inner field, cut into squares of stretch_length) at once. The earliest conflict
//     is removed by the smallest planned wait at the start (in steps of wait_step) of the lower-priority robot of
//     the pair (the one later in route order) that leaves the pair without a conflict over the whole plan, or
//     else of the other one; repeated until none is left or no wait up to max_wait helps (reported).
//   * Figures (fleetFigures): area rate = the tool's working width times the tool-down length / time, per robot
//     (its driving time) and for the fleet (the makespan, waits included), and energy per hectare from the
//     motors' electrical power along the timed paths (fleetEnergy).
// All pure functions of their arguments; errors as std::invalid_argument with one line.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/model/motor.h"
#include "sowing_robot/core/model/robot_params.h"
#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/core/planning/path_plan.h"

namespace sowing_robot {
namespace core {

struct FleetParams {
  double safety_distance = 2.0;  ///< [m] no two robots closer (two working widths of the 1 m drill)
  double stretch_length = 10.0;  ///< [m] side of a headland stretch
  double time_step = 0.25;       ///< [s] sampling of the timed paths for the check
  double wait_step = 5.0;        ///< [s] waits are multiples of it (rounded to a multiple of time_step)
  double max_wait = 3600.0;      ///< [s] the longest wait tried for one robot
  std::string validate() const;
};

/// One robot's share.
struct RobotShare {
  int robot = 0;        ///< index into the start poses
  int rank = 0;         ///< its block's place in route order: 0 first, the highest priority
  int first_swath = 0;  ///< its swaths: plan.swaths[first_swath, first_swath + swaths)
  int swaths = 0;
  std::vector<int> loops;  ///< plan.headland_rings indices, in the order driven
  Pose2D start;
  CoveragePath path;      ///< from the start pose: approach, swaths with their turns, joins and loops
  PathPlan timed;         ///< path through the follower from the start at rest
  double estimate = 0.0;  ///< the split's estimate of its driving time [s]
  double wait = 0.0;      ///< planned wait at the start pose before it drives [s]
  double end() const { return wait + timed.duration(); }  ///< [s] from the fleet's start
  /// Where it is t seconds after the fleet's start: its start pose while waiting, its last pose once finished.
  Pose2D poseAt(double t) const { return timed.at(t - wait).pose; }
};

/// A conflict of the check: the first sample of it.
struct FleetConflict {
  int a = 0, b = 0;       ///< shares (indices into FleetPlan::shares), a < b
  double time = 0.0;      ///< [s] from the fleet's start
  double distance = 0.0;  ///< [m]
  bool headland = false;  ///< the same headland stretch (else closer than the safety distance)
};

struct FleetCheck {
  std::vector<FleetConflict> conflicts;  ///< every sample in conflict, by time (capped at 1000)
  double min_separation = 0.0;           ///< [m] closest two robots both driving (+inf when never)
  double min_separation_time = 0.0;
  int min_a = -1, min_b = -1;
};

/// A wait keepApart planned: which share waits how much longer, for which conflict.
struct FleetWait {
  int share = 0;
  double added = 0.0;  ///< [s] added to its wait
  FleetConflict conflict;
};

struct FleetPlan {
  std::vector<RobotShare> shares;  ///< in route order of their blocks (share i has rank i)
  PathParams follower;             ///< the follower's parameters the times are planned with
  double makespan() const;         ///< [s] the last robot's end
  /// keepApart's outcome: waits added, and whether the plan ended conflict-free.
  int waits_added = 0;
  std::vector<FleetWait> waits;  ///< in the order they were added
  bool conflict_free = false;
  FleetCheck check;  ///< the last check (keepApart's)
};

/// The plan's swaths and loops split among `robots` robots starting at `starts` (one pose each). Throws
/// std::invalid_argument when robots < 1, robots > 8 or more than the swaths, starts.size() != robots, a start is not
/// finite, params or follower are invalid, or the plan has no swaths.
FleetPlan splitCoverage(const CoveragePlan& plan, int robots, const std::vector<Pose2D>& starts,
                        const CoverageParams& params, const PathParams& follower);

/// The conflicts of the fleet's timed paths (see the file comment); waits as set in the shares.
FleetCheck checkFleet(const FleetPlan& fleet, const CoveragePlan& plan, const FleetParams& params);

/// Adds planned waits until checkFleet finds no conflict (see the file comment); sets waits_added, conflict_free
/// and check. Throws std::invalid_argument for invalid params.
void keepApart(FleetPlan& fleet, const CoveragePlan& plan, const FleetParams& params);

/// The drive's electrical energy model (there is no electrical power in model/motor.h: it models the torque band
/// only). Per wheel, the torque tau the planned motion needs: the wheel's share of m0 v_dot (half), of the yaw
/// I0 omega_dot (+-1/(2L)), of the rolling resistance (rolling_resistance m g split evenly on the two wheels,
/// against each wheel's own rolling) and of the tool's draft when it is down (half, against the motion), times R.
/// A DC motor seen at the wheel (motor.h: stall torque tau_s, no-load speed W_0 at the bus voltage) draws
/// P = tau W + tau^2 W_0 / tau_s: the mechanical power plus the winding's copper loss (R/k^2 = W_0 / tau_s at the
/// wheel; the gearbox's efficiency is in tau_s). Braking is not fed back: P < 0 counts 0.
struct DriveEnergyParams {
  RobotParams robot;
  MotorParams motor;
  double rolling_resistance = 0.05;  ///< traction/rolling_resistance
  double draft_force = 0.0;          ///< traction/draft_force [N] while the tool is down
  double gravity = 9.81;             ///< [m/s^2]
};
/// Electrical energy [J] of driving `timed` from its start to its end, integrated every dt seconds (midpoints).
double driveEnergy(const PathPlan& timed, const DriveEnergyParams& params, double dt = 0.1);

struct RobotFigures {
  double area = 0.0;           ///< [m^2] working width x tool-down length of its path
  double time = 0.0;           ///< [s] driving (the wait excluded)
  double wait = 0.0;           ///< [s]
  double area_rate = 0.0;      ///< [ha/h] area / driving time
  double energy = 0.0;         ///< [Wh]
  double energy_per_ha = 0.0;  ///< [Wh/ha]
};
struct FleetFigures {
  std::vector<RobotFigures> robots;          ///< per share
  double area = 0.0, makespan = 0.0;         ///< [m^2], [s]
  double area_rate = 0.0;                    ///< [ha/h] area / makespan
  double energy = 0.0, energy_per_ha = 0.0;  ///< [Wh], [Wh/ha]
};
/// The fleet's figures with the tool's working width [m].
FleetFigures fleetFigures(const FleetPlan& fleet, double working_width, const DriveEnergyParams& energy);

/// Working width x tool-down length of a path [m^2].
double toolArea(const CoveragePath& path, double working_width);

}  // namespace core
}  // namespace sowing_robot
