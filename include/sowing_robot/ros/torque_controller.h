// torque_controller: desired + measured velocities -> wheel torques. The inner controller is chosen by
// `inner`: the sliding-mode controller (eqs 4.7-4.22; `mode` atsmc or tsmc) or the wheel-velocity PID
// (core/control/wheel_pid.h), each with its gains live-tunable by dynamic_reconfigure (cfg/TorqueController.cfg,
// cfg/WheelPid.cfg: the server of the controller in use). Publishes its state on ~state: the
// sliding variables and adaptive estimates, or for the PID the same record with s_v = s_omega = 0 and
// the nominal m0, I0 (core/control/controllers.h, InnerOutput).
//
// Traction control (traction_control/..., core/control/traction_control.h; off by default: today's torques)
// caps each wheel's torque while it slips, after the inner loop, exactly as the in-process loop does
// (core/simulation/closed_loop.h). Its slip estimate takes each wheel's speed from the encoders (`odom`, the
// plant's encoder odometry: R W = v ± L w of its twist) and the ground speed from the fed state (`feedback`:
// the truth, the odometry or the estimate), never the plant's hidden state; with feedback other than odom it
// pairs the two by stamp. Each period's verdict goes out on `traction_control/state` (latched, before the
// torque) for the reference generator's speed governor.
// No traction (traction_control/no_traction_*, core/control/traction_monitor.h), as the in-process loop: the
// progress check on the fed pose and the slip verdict; from the period after its verdict the inner loop is
// given the hold command (the standstill hold brakes the robot where it is, whatever the desired velocity), the
// report is logged once (ERROR) and carried by every later traction_control/state, and run_monitor ends the run
// no_traction_hold after the verdict; should the plant go on (exit_at_end false), the hold goes on.
#pragma once

#include <dynamic_reconfigure/server.h>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include "sowing_robot/ros/common/reconfigure_bridge.h"

#include <deque>
#include <memory>
#include <optional>

#include "sowing_robot/DesiredVelocity.h"
#include "sowing_robot/TorqueControllerConfig.h"
#include "sowing_robot/TorqueControllerState.h"
#include "sowing_robot/TractionControlState.h"
#include "sowing_robot/WheelPidConfig.h"
#include "sowing_robot/WheelTorque.h"
#include "sowing_robot/core/control/controller_factory.h"
#include "sowing_robot/core/control/hitch_control.h"
#include "sowing_robot/core/control/sliding_mode.h"
#include "sowing_robot/core/control/standstill_hold.h"
#include "sowing_robot/core/control/traction_control.h"
#include "sowing_robot/core/control/traction_monitor.h"
#include "sowing_robot/ros/common/ready_roster.h"
#include "sowing_robot/ros/common/stamp_pair.h"

namespace sowing_robot {

class TorqueController {
 public:
  TorqueController(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  void odomCallback(const nav_msgs::Odometry::ConstPtr& msg);
  /// Traction control with feedback other than odom: the encoders' odometry, paired with the fed state.
  void encoderCallback(const nav_msgs::Odometry::ConstPtr& msg);
  /// The fed state `fed` on to the pair with the desired velocity; `encoders`: the odom message of its stamp
  /// (the traction control's wheel speeds), kept until that stamp is computed.
  void feed(const nav_msgs::Odometry& fed, const nav_msgs::Odometry& encoders);
  void desiredCallback(const DesiredVelocity::ConstPtr& msg);
  void compute();
  /// The traction control on the inner loop's torques for the fed state `fed` (its wheel speeds from
  /// wheel_speeds_); publishes its state; returns the torques to send.
  /// `driving`: the command is not a hold (the progress check rests at a stop).
  core::WheelTorques limitTraction(const core::WheelTorques& requested, const nav_msgs::Odometry& fed, bool driving);
  /// Realtime only: zero torque for this odom stamp when the desired velocity is older than input_timeout.
  bool holdZeroIfStale(const nav_msgs::Odometry& odom);

  std::unique_ptr<core::InnerController> inner_;
  core::SlidingModeController* smc_ = nullptr;  // inner_'s sliding-mode controller (live gains), else null
  core::WheelPid* pid_ = nullptr;               // inner_'s PID, else null
  double hold_max_torque_ = 0.0;                // max_torque: the motors' limit, whichever controller runs
  std::unique_ptr<core::StandstillHold> hold_;  // the brake at a stop (desired_velocity's hold)
  bool holding_ = false;                        // the last period was a hold
  double dt_ = 0.001;
  bool lockstep_;               // run/mode: wait for the paired desired velocity, never time out
  double input_timeout_ = 0.1;  // [s] sim
  bool stale_ = false;          // the last output was the zero hold
  // Live gains (reconfigure_bridge.h): validated like the start-up values, a rejected change keeps the old.
  std::unique_ptr<ReconfigureServer<TorqueControllerConfig>> smc_reconfigure_;
  std::unique_ptr<ReconfigureServer<WheelPidConfig>> pid_reconfigure_;
  ros::Subscriber odom_sub_, desired_sub_, encoder_sub_;
  ros::Publisher torque_pub_, state_pub_, traction_pub_;
  // Traction control (unset: off).
  std::optional<core::TractionControl> traction_control_;
  std::optional<core::TractionMonitor> traction_monitor_;  ///< with the traction control: the no-traction check
  // Slip-limit hitch control (hitch_control/...; unset: off): on the traction control's grip verdict, its
  // command goes to plant_sim with the torque (WheelTorque/tool_raised).
  std::optional<core::HitchControl> hitch_;
  double L_ = 0.0;            // nominal half track [m] (URDF): R W = v ± L w of the encoders' twist
  bool fed_is_odom_ = false;  // the feedback topic is odom itself: no pairing needed
  // The standstill hold closes its along axis on the encoders' wheel speeds and the traction control does not cap
  // it: fed the EKF with the traction control on (LoopLayers::hold_on_wheels, closed_loop.h).
  bool hold_on_wheels_ = false;
  StampPair<nav_msgs::Odometry, nav_msgs::Odometry, 16, 16> fed_encoders_;  // (feedback, odom) by stamp
  struct WheelSpeeds {
    ros::Time stamp;
    double right, left;  // R W [m/s]
  };
  std::deque<WheelSpeeds> wheel_speeds_;  // of the fed states on their way to a pair, oldest first
  TractionControlState traction_state_;
  StampPair<nav_msgs::Odometry, DesiredVelocity> inputs_;
  WheelTorque torque_;
  TorqueControllerState state_;
  long rejected_ = 0, saturated_ = 0;
  ReadyAnnouncer ready_;  // plant_sim waits for it before step 0
};

}  // namespace sowing_robot
