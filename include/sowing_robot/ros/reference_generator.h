// reference_generator: publishes the reference posture, velocities and accelerations for every state
// the plant publishes (same stamp), plus the reference path for rviz.
#pragma once

#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>

#include <memory>

#include "sowing_robot/ReferenceState.h"
#include "sowing_robot/core/reference.h"

namespace sowing_robot {

class ReferenceGenerator {
 public:
  ReferenceGenerator(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  void odomCallback(const nav_msgs::Odometry::ConstPtr& msg);

  std::unique_ptr<core::ReferenceSource> source_;
  ros::Subscriber odom_sub_;
  ros::Publisher ref_pub_, path_pub_;
  ReferenceState ref_;
  nav_msgs::Path path_;
  bool any_ = false;
  double path_spacing_ = 0.1;  // [m] between stored reference path points
};

}  // namespace sowing_robot
