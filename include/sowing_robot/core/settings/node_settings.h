// What each node reads besides the core components it wraps: the run-wide settings (set once per run,
// read by every node) and each node's own timing and I/O. Plain data with a parameter table each, so
// the ROS loader, the error texts, the logs and docs/parameters.md follow from one declaration, and
// the docs tool needs no ROS. Components (gains, disturbance, field, seeding) are nested tables.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/control/command_limits.h"
#include "sowing_robot/core/control/controller_factory.h"
#include "sowing_robot/core/control/kanayama.h"
#include "sowing_robot/core/control/sliding_mode.h"
#include "sowing_robot/core/control/standstill_hold.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/seeding.h"

namespace sowing_robot {
namespace core {

/// Run-wide settings, under `run/` relative to each node's namespace (sim.launch sets them once).
struct RunSettings {
  RunSettings();
  bool lockstep;                         ///< mode: lockstep (headless) or realtime (paced to the wall clock)
  double control_rate;                   ///< plant step and control rate [Hz]
  double duration;                       ///< scenario length [s]; 0 = forever
  std::string odom_frame, base_frame;    ///< REP-105 frame ids
  double start_x, start_y, start_theta;  ///< where the robot starts (the plant) and the approach begins (the field)
  Pose2D start() const { return {start_x, start_y, start_theta}; }
  std::string validate() const { return table().checkRanges(*this, "run/"); }
  /// The control period on the ns grid every node stamps its messages on.
  std::int64_t periodNs() const;
  static const ParamTable<RunSettings>& table();
};

/// plant_sim: timing of the two drivers, start pose, and the disturbance (nested).
struct PlantSimSettings {
  PlantSimSettings();
  double realtime_factor, torque_timeout, publish_rate, clock_rate;
  double lockstep_retry, lockstep_timeout, lockstep_give_up, startup_delay, max_speed;
  int min_subscribers;
  std::string wait_for;    ///< space-separated node names (ros/common/ready_roster.h)
  std::string loop_topic;  ///< plant_sim's topic the controllers' feedback comes from: ground_truth | odom
  bool exit_at_end;
  bool start_at_route;  ///< start where reference_generator's coverage route begins (ros/coverage_route.h)
  PlantDisturbance disturbance;
  std::string validate() const;
  /// wait_for split at white space.
  std::vector<std::string> waitForNames() const;
  static const ParamTable<PlantSimSettings>& table();
};

/// kinematic_controller: which outer controller (`outer`) and every registered outer controller's
/// parameters (ControllerPair, controller_factory.h; flat keys: the Kanayama gains, nav2's names for the
/// pure pursuit / RPP), the command limits and the reference timeout. Every parameter is read and checked
/// whatever `outer` is; only the selected controller's are used (the others are inert).
struct KinematicControllerSettings : ControllerPair {
  KinematicControllerSettings();
  double input_timeout;
  CommandLimitsParams limits;  ///< limits/: bounds on the command handed on (whichever controller runs)
  /// Ranges (the table), then every outer controller's own checks (even when not selected).
  std::string validate() const;
  static const ParamTable<KinematicControllerSettings>& table();
};

/// torque_controller: which inner controller (`inner`: sliding_mode, whose `mode` picks atsmc or tsmc,
/// or pid) and every registered inner controller's parameters (flat keys), the standstill hold and the
/// desired-velocity timeout. `max_torque` is the motor's per-wheel limit, one key for every controller. As
/// for the kinematic controller, the parameters of the controllers not selected are checked but inert.
struct TorqueControllerSettings : ControllerPair {
  TorqueControllerSettings();
  double input_timeout;
  StandstillHoldParams hold;  ///< the standstill hold at a stop (either controller)
  std::string validate() const;
  /// "atsmc", "tsmc" or "pid": the pair's inner name.
  std::string innerName() const { return core::innerName(inner, sliding.adaptive); }
  static const ParamTable<TorqueControllerSettings>& table();
};

/// reference_generator: the reference type and its line; the field (FieldParams, fieldTable()) and the
/// obstacles are read only with type field, the path's keys (PathParams, pathTable(), and path/points) only
/// with type path.
struct ReferenceGeneratorSettings {
  enum class Type { kLine, kField, kPath, kCoverage };
  ReferenceGeneratorSettings();
  /// line (the thesis line), field (rows and turns, field/follower), path (a given path, path_plan.h) or coverage
  /// (a field file planned by the coverage planner, coverage_planner.h, and followed as a path)
  Type type;
  double line_x0, line_v_r, line_y;
  std::string field_file;    ///< type coverage: the field file (docs/field_file.md)
  std::string field_origin;  ///< type coverage: "LAT,LON[,ALT]" in place of a GeoJSON file's origin, or ""
  double path_spacing, lookahead;
  std::string validate() const { return table().checkRanges(*this); }
  static const ParamTable<ReferenceGeneratorSettings>& table();
};

/// seed_drill: the seeding parameters (nested) and the URDF link of the seed-drop point.
struct SeedDrillSettings {
  SeedDrillSettings();
  std::string tool_link;
  bool follow_hitch;
  double marker_size;  ///< rviz only: the seeds' sphere diameter
  SeedingParams seeding;
  std::string validate() const { return table().checkRanges(*this); }
  static const ParamTable<SeedDrillSettings>& table();
};

/// state_estimator's own keys (the filter's are core/estimation/ekf.h's ekfTable()).
struct StateEstimatorSettings {
  StateEstimatorSettings();
  std::string fix_source;
  std::string validate() const { return table().checkRanges(*this); }
  static const ParamTable<StateEstimatorSettings>& table();
};

/// run_monitor: where the metrics go and whether the run ends with them.
struct RunMonitorSettings {
  RunMonitorSettings();
  std::string label, output, recorder;
  bool time_domain, exit_at_end;
  double recorder_timeout;
  std::string validate() const { return table().checkRanges(*this); }
  static const ParamTable<RunMonitorSettings>& table();
};

/// fleet_monitor (fleet.launch): the fleet's size, its safety distance, and whether it ends the launch.
struct FleetMonitorSettings {
  FleetMonitorSettings();
  int robots;
  double safety_distance;
  bool exit_at_end;
  bool yield;  ///< decide who holds (FleetYield) on every decision stamp and publish the verdicts
  double yield_distance, yield_hysteresis, decision_period;
  std::string validate() const { return table().checkRanges(*this); }
  static const ParamTable<FleetMonitorSettings>& table();
};

/// pso_tuner (offline): the swarm, the cost and the simulated run of each evaluation. The base scenario
/// comes from the run and node settings; the search box is the `gains` list (tuning.h).
struct PsoTunerSettings {
  PsoTunerSettings();
  int particles, iterations, seed, threads;
  double velocity_clamp, w_max, w_min, c1, c2;
  bool adaptive;           ///< mode: the controller tuned
  std::string controller;  ///< "outer+inner" tuned; "" = kanayama + mode
  double duration, control_rate;
  std::string cost, output;
  double torque_weight, chattering_weight;
  std::string validate() const;
  static const ParamTable<PsoTunerSettings>& table();
};

}  // namespace core
}  // namespace sowing_robot
