// seed_drill: the plant-side seed drill. Follows the tool point (URDF `tool_link`) on odom, drops a seed
// every `spacing` metres while the tool is down, shows the seeds in rviz and reports the cross-track
// error of the sown line against the intended rows (away from obstacles and in detours apart).
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <visualization_msgs/Marker.h>

#include <memory>

#include "sowing_robot/ReferenceState.h"
#include "sowing_robot/core/seeding.h"

namespace sowing_robot {

class SeedDrillNode {
 public:
  SeedDrillNode(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~SeedDrillNode();

 private:
  void odomCallback(const nav_msgs::Odometry::ConstPtr& msg);
  void referenceCallback(const ReferenceState::ConstPtr& msg) { tool_down_ = msg->tool_down; }
  void publishReport();

  std::unique_ptr<core::SeedDrill> drill_;
  double tool_x_ = 0.0, tool_y_ = 0.0;  // tool point in base_link [m]
  bool tool_down_ = false;
  ros::Subscriber odom_sub_, ref_sub_;
  ros::Publisher seeds_pub_, report_pub_;
  visualization_msgs::Marker chunk_;  // the current SPHERE_LIST of up to kChunk seeds
  int chunk_id_ = 0;
  std::size_t seeds_ = 0;
};

}  // namespace sowing_robot
