// torque_controller: desired + measured velocities -> wheel torques. The inner controller is chosen by
// `inner`: the sliding-mode controller (eqs 4.7-4.22; `mode` atsmc or tsmc) or the wheel-velocity PID
// (core/control/wheel_pid.h), each with its gains live-tunable by dynamic_reconfigure (cfg/TorqueController.cfg,
// cfg/WheelPid.cfg: the server of the controller in use). Publishes its state on ~state: the
// sliding variables and adaptive estimates, or for the PID the same record with s_v = s_omega = 0 and
// the nominal m0, I0 (core/control/controllers.h, InnerOutput).
#pragma once

#include <dynamic_reconfigure/server.h>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include "sowing_robot/ros/common/reconfigure_bridge.h"

#include <memory>

#include "sowing_robot/DesiredVelocity.h"
#include "sowing_robot/TorqueControllerConfig.h"
#include "sowing_robot/TorqueControllerState.h"
#include "sowing_robot/WheelPidConfig.h"
#include "sowing_robot/WheelTorque.h"
#include "sowing_robot/core/control/controllers.h"
#include "sowing_robot/core/control/sliding_mode.h"
#include "sowing_robot/core/control/standstill_hold.h"
#include "sowing_robot/ros/common/ready_roster.h"
#include "sowing_robot/ros/common/stamp_pair.h"

namespace sowing_robot {

class TorqueController {
 public:
  TorqueController(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  void odomCallback(const nav_msgs::Odometry::ConstPtr& msg);
  void desiredCallback(const DesiredVelocity::ConstPtr& msg);
  void compute();
  /// Realtime only: zero torque for this odom stamp when the desired velocity is older than input_timeout.
  bool holdZeroIfStale(const nav_msgs::Odometry& odom);

  std::unique_ptr<core::InnerController> inner_;
  core::SlidingModeController* smc_ = nullptr;  // inner_'s sliding-mode controller (live gains), else null
  core::WheelPid* pid_ = nullptr;               // inner_'s PID, else null
  std::unique_ptr<core::StandstillHold> hold_;  // the brake at a stop (desired_velocity's hold)
  bool holding_ = false;                        // the last period was a hold
  double dt_ = 0.001;
  bool lockstep_;               // run/mode: wait for the paired desired velocity, never time out
  double input_timeout_ = 0.1;  // [s] sim
  bool stale_ = false;          // the last output was the zero hold
  // Live gains (reconfigure_bridge.h): validated like the start-up values, a rejected change keeps the old.
  std::unique_ptr<ReconfigureServer<TorqueControllerConfig>> smc_reconfigure_;
  std::unique_ptr<ReconfigureServer<WheelPidConfig>> pid_reconfigure_;
  ros::Subscriber odom_sub_, desired_sub_;
  ros::Publisher torque_pub_, state_pub_;
  StampPair<nav_msgs::Odometry, DesiredVelocity> inputs_;
  WheelTorque torque_;
  TorqueControllerState state_;
  long rejected_ = 0, saturated_ = 0;
  ReadyAnnouncer ready_;  // plant_sim waits for it before step 0
};

}  // namespace sowing_robot
