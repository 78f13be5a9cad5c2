// cmd_vel_limiter: velocity mode (sim.launch input:=cmd_vel, docs/interfaces.md). Takes velocity commands,
// geometry_msgs/Twist on `cmd_vel` or TwistStamped on `cmd_vel_stamped`, and hands the inner loop what the
// kinematic controller would: for every state on `feedback`, a desired_velocity with the same stamp, the
// limited v and omega and their analytic accelerations (core/control/cmd_vel_input.h: the limiter, the
// command timeout). A node of its own, not a mode of kinematic_controller: it tracks no reference, has
// no tracking error and no gains, and its state (the limiter's profile) has nothing to do with the outer
// controllers', so each node keeps one job and one parameter table.
//
// realtime: a Twist acts from the newest state's stamp on; a TwistStamped from its stamp (simulated time;
//   zero: as a Twist). Each state is answered at once.
// lockstep: only TwistStamped counts (a Twist has no stamp to pair by). The state stamped t is answered
//   once a twist stamped t or later has come, so the run is a function of the stamped commands and
//   repeats bit for bit; a source that reacts to the state at t answers it with a twist stamped t.
#pragma once

#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include <optional>

#include "sowing_robot/DesiredVelocity.h"
#include "sowing_robot/core/control/cmd_vel_input.h"
#include "sowing_robot/ros/common/ready_roster.h"

namespace sowing_robot {

class CmdVelLimiter {
 public:
  CmdVelLimiter(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  void stateCallback(const nav_msgs::Odometry::ConstPtr& msg);
  void twistCallback(const geometry_msgs::Twist::ConstPtr& msg);
  void stampedCallback(const geometry_msgs::TwistStamped::ConstPtr& msg);
  /// Offers one twist to the input; a refused one is dropped with a throttled warning.
  void offer(const ros::Time& stamp, const geometry_msgs::Twist& twist, const char* topic);
  /// The desired velocity for the state stamped `stamp`, published.
  void answer(const ros::Time& stamp);
  /// True at most once a second of wall time (then `last` is now): a throttle for warnings about inputs.
  /// Not ROS_WARN_THROTTLE's simulated time: it stands still while lockstep waits, and a throttle on it
  /// stays silent for the first simulated second, when a lockstep source sends its commands.
  static bool throttle(ros::WallTime& last);

  std::optional<core::CmdVelInput> input_;  // set by the constructor once its parameters are read
  bool lockstep_;
  bool answered_ = false;  // desired_ answers the state stamped last_
  ros::Time last_;
  bool pending_ = false;  // lockstep: the state stamped pending_stamp_ waits for its twist
  ros::Time pending_stamp_;
  bool wait_reported_ = false;  // for pending_stamp_
  bool stale_reported_ = false;
  long dropped_ = 0;
  // throttle(), one per warning: a shared one let a stamped-0 twist hide the plain-Twist warning
  ros::WallTime dropped_log_, plain_log_, unstamped_log_;
  DesiredVelocity desired_;
  ros::Publisher desired_pub_;
  ros::Subscriber state_sub_, twist_sub_, stamped_sub_;
  ReadyAnnouncer ready_;  // plant_sim waits for it before step 0
};

}  // namespace sowing_robot
