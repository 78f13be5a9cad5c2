// One loader per core component: parameter names, defaults and units live here and in the core
// params structs (whose validate() holds the ranges). Nodes, the PSO tuner and the pipeline test all
// load through these, so a gain means the same thing everywhere.
#pragma once

#include <cstdint>
#include <string>

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

/// Everything one node needs checked: reader errors, unknown keys, then the given validate() text.
/// Refuses to start (exit 1) on the first problem.
void requireValid(const ParamReader& p, const std::string& validate_message);

/// The scenario the node pipeline runs, read from the nodes' own namespaces (/plant_sim,
/// /kinematic_controller, /torque_controller): what the in-process runner needs to repeat a run.
std::string loadPipelineScenario(core::Scenario& sc, double& duration);

}  // namespace sowing_robot
