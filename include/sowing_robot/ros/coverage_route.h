// type coverage's route, planned the same way wherever it is needed: reference_generator follows it and plant_sim
// starts the robot where it begins (plant_sim/start_at_route). Both read reference_generator's keys (field_file,
// field_origin, coverage/..., the field's speeds, fleet/...), and planning is a pure function of them, so both get the
// same start pose.
//   fleet/robots 0: the whole route, from its own start (routeStart: no approach).
//   fleet/robots N: the plan split among N robots (core/planning/fleet_share.h); this robot's share (fleet/index),
//                   from its start pose, after its planned wait.
#pragma once

#include <ros/ros.h>

#include <string>

#include "sowing_robot/core/planning/coverage_planner.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/fleet_share.h"
#include "sowing_robot/core/settings/node_settings.h"
#include "sowing_robot/ros/common/param_reader.h"

namespace sowing_robot {

struct CoverageRoute {
  core::FieldParams field;  ///< the speeds only (row_speed, turn_speed, max_accel)
  core::CoverageParams coverage;
  core::FleetShareParams fleet;
  core::CoveragePlan plan;
  core::FleetShare share;     ///< fleet.robots > 0
  core::Pose2D start;         ///< where the robot starts
  core::CoveragePath path;    ///< what it drives from there
  double wait = 0.0;          ///< [s] standing at the start first
  core::PathParams follower;  ///< coverageFollowerParams
};

/// Of the field's keys, type coverage reads the speeds only; its other field/ keys are refused as unknown.
const core::ParamTable<core::FieldParams>& coverageFieldSpeedsTable();

/// Reads the keys through p (reference_generator's private handle; nh: the robot's namespace, for the URDF's tool
/// run-out) and plans. "" or one line: a key's problem, or the file's or the planner's after the file's name.
std::string loadCoverageRoute(ParamReader& p, const ros::NodeHandle& nh,
                              const core::ReferenceGeneratorSettings& settings, CoverageRoute& out);

}  // namespace sowing_robot
