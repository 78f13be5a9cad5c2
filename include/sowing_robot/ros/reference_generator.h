// reference_generator: publishes the reference posture, velocities and accelerations for every state
// the plant publishes (same stamp), plus the reference path for rviz. With `lookahead` (default) the
// reference for t_k + 1/control_rate goes out together with the one for t_k: an obstacle or gain change
// then takes effect one period later, and the loop does not wait for this node.
//   type line:  core::LineReference (the thesis's sowing line).
//   type field: core::FieldReference (rows + headland turns through the potential field) with the
//               obstacles from the `obstacles` parameter; `obstacles` (MarkerArray) replaces them at
//               run time, and `field_markers` (latched) shows obstacles, influence zones and rows.
#pragma once

#include <dynamic_reconfigure/server.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "sowing_robot/ReferenceGeneratorConfig.h"
#include "sowing_robot/ReferenceState.h"
#include "sowing_robot/core/field.h"
#include "sowing_robot/core/reference.h"
#include "sowing_robot/ros/path_buffer.h"

namespace sowing_robot {

class ReferenceGenerator {
 public:
  ReferenceGenerator(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  void odomCallback(const nav_msgs::Odometry::ConstPtr& msg);
  /// The source's reference at stamp into out.
  void fill(ReferenceState& out, const ros::Time& stamp);
  /// type field: every ADD CYLINDER marker is an obstacle (centre = pose.position, radius = scale.x / 2);
  /// the message replaces the whole list. A message with a non-finite or non-positive value is dropped.
  void obstaclesCallback(const visualization_msgs::MarkerArray::ConstPtr& msg);
  /// type field: obstacles, influence zones and row lines on field_markers.
  void publishMarkers();
  /// type field: live avoidance gains, validated like the start-up values (a rejected change keeps them).
  void reconfigure(ReferenceGeneratorConfig& config, uint32_t level);

  std::unique_ptr<core::ReferenceSource> source_;
  core::FieldReference* field_ = nullptr;  ///< source_ when type is field, else null
  std::vector<core::Obstacle> obstacles_;  ///< the obstacles in force (type field)
  ros::Subscriber odom_sub_, obstacles_sub_;
  ros::Publisher ref_pub_, path_pub_, marker_pub_;
  ReferenceState ref_;    ///< reference for the newest state
  ReferenceState ahead_;  ///< reference for one period after it (lookahead), already published
  bool ahead_valid_ = false;
  bool lookahead_ = true;
  std::int64_t period_ns_ = 1000000;  ///< control period (control_rate) [ns]
  std::unique_ptr<PathBuffer> path_;  // reference_path (spacing from the parameters)
  bool any_ = false;
  double path_spacing_ = 0.1;  // [m] between stored reference path points
  std::unique_ptr<dynamic_reconfigure::Server<ReferenceGeneratorConfig>> reconfigure_;  // type field only
};

}  // namespace sowing_robot
