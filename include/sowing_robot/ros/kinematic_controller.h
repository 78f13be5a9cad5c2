// kinematic_controller: reference + odom -> desired body velocities and the tracking error for plotting
// and metrics. The outer controller is chosen by `outer`: Kanayama (eqs 4.1-4.2), pure pursuit or nav2's
// Regulated Pure Pursuit (core/control/pure_pursuit.h), each live-tunable by dynamic_reconfigure
// (cfg/KinematicController.cfg, cfg/PurePursuit.cfg: the server of the controller in use).
#pragma once

#include <dynamic_reconfigure/server.h>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include "sowing_robot/ros/common/reconfigure_bridge.h"

#include <memory>

#include "sowing_robot/DesiredVelocity.h"
#include "sowing_robot/KinematicControllerConfig.h"
#include "sowing_robot/PurePursuitConfig.h"
#include "sowing_robot/ReferenceState.h"
#include "sowing_robot/TrackingError.h"
#include "sowing_robot/core/control/command_limits.h"
#include "sowing_robot/core/control/controller_factory.h"
#include "sowing_robot/core/control/kanayama.h"
#include "sowing_robot/core/control/pure_pursuit.h"
#include "sowing_robot/ros/common/ready_roster.h"
#include "sowing_robot/ros/common/stamp_pair.h"

namespace sowing_robot {

class KinematicController {
 public:
  KinematicController(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  void odomCallback(const nav_msgs::Odometry::ConstPtr& msg);
  void referenceCallback(const ReferenceState::ConstPtr& msg);
  void compute();
  /// Realtime only: command a stop for this odom stamp when the reference is older than input_timeout.
  void stopIfStale(const nav_msgs::Odometry& odom);

  std::unique_ptr<core::OuterController> outer_;
  std::unique_ptr<core::CommandLimiter> limiter_;  // limits/ (passes the command unchanged when off)
  double period_ = 0.0;                            // [s] between two states: the limiter's dt (run/control_rate)
  core::Kanayama* kanayama_ = nullptr;             // outer_'s Kanayama when outer is kanayama, else null
  core::PurePursuit* pure_pursuit_ = nullptr;      // outer_'s (R)PP when outer is pure_pursuit or rpp, else null
  ros::Subscriber odom_sub_, ref_sub_;
  ros::Publisher desired_pub_, error_pub_;
  bool grid_reported_ = false;  // a control_rate mismatch is reported once
  StampPair<nav_msgs::Odometry, ReferenceState> inputs_;
  DesiredVelocity desired_;
  TrackingError error_;
  long rejected_ = 0;
  bool lockstep_;                // run/mode: wait for the paired reference, never time out
  double input_timeout_ = 0.05;  // [s] sim (shorter than torque_controller's: see config/controllers.yaml)
  // Live gains (reconfigure_bridge.h): validated like the start-up values, a rejected change keeps the old.
  std::unique_ptr<ReconfigureServer<KinematicControllerConfig>> kanayama_reconfigure_;
  std::unique_ptr<ReconfigureServer<PurePursuitConfig>> pure_pursuit_reconfigure_;
  ReadyAnnouncer ready_;  // plant_sim waits for it before step 0
};

}  // namespace sowing_robot
