// One loader per core component: parameter names, defaults and units live here and in the core
// params structs (whose validate() holds the ranges). Nodes, the PSO tuner and the pipeline test all
// load through these, so a gain means the same thing everywhere.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sowing_robot/core/field.h"
#include "sowing_robot/core/kanayama.h"
#include "sowing_robot/core/plant.h"
#include "sowing_robot/core/robot_params.h"
#include "sowing_robot/core/runner.h"
#include "sowing_robot/core/sliding_mode.h"
#include "sowing_robot/ros/param_reader.h"

namespace sowing_robot {

/// Robot geometry and inertia from the URDF in `robot_description` (searched upwards from nh).
std::string loadRobotParams(const ros::NodeHandle& nh, core::RobotParams& out);

/// control_rate [Hz] -> control period [ns]; 0 on a bad rate (error set in the reader's message).
std::int64_t loadControlPeriod(ParamReader& p, std::string& error);

/// disturbance/{sinusoidal, amplitude, frequency}, noise/{std, seed}, mismatch/{mass_scale, inertia_scale}.
core::PlantDisturbance loadDisturbance(ParamReader& p);

/// kx, ky, ktheta.
core::KanayamaGains loadKanayama(ParamReader& p);

/// mode (atsmc|tsmc), p, q, beta_v, beta_omega, k1, k2, eta1, eta2, rate_m, rate_i, m0_min, m0_max,
/// i0_min, i0_max, m0_initial, i0_initial, max_torque, switching (sign|sat|relay|atan|tanh), switch_width.
core::SlidingModeParams loadSlidingMode(ParamReader& p, std::string& error);

/// start/{x, y, theta}.
core::Pose2D loadStartPose(ParamReader& p);

/// potential/{alpha, beta, influence_distance, gain, tangential_ratio, nearest_side, avoid_side (left|right),
/// side_band, core_fraction, step, heading_hold_speed}.
core::PotentialFieldParams loadPotentialField(ParamReader& p, std::string& error);

/// field/{rows, row_length, row_spacing, start_x, start_y, heading, rows_to_left, row_speed, turn_speed,
/// min_turn_radius, max_accel, max_curvature_rate, start_from_rest} plus potential/ (loadPotentialField).
core::FieldParams loadFieldParams(ParamReader& p, std::string& error);

/// The list `key` of {x, y, radius} maps (radius optional, default core::Obstacle's); marks `key` as read.
/// Returns "" or one line naming the bad entry (absent key: empty list).
std::string loadObstacles(ParamReader& p, const std::string& key, std::vector<core::Obstacle>& out);

/// Everything one node needs checked: reader errors, unknown keys, then the given validate() text.
/// Refuses to start on the first problem: throws badParameter (node_failure.h).
void requireValid(const ParamReader& p, const std::string& validate_message);

/// The scenario the node pipeline runs, read from the nodes' own namespaces (/plant_sim,
/// /kinematic_controller, /torque_controller): what the in-process runner needs to repeat a run.
std::string loadPipelineScenario(core::Scenario& sc, double& duration);

}  // namespace sowing_robot
