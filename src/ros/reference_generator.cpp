#include "sowing_robot/ros/reference_generator.h"

#include <cmath>

#include "sowing_robot/core/validation.h"
#include "sowing_robot/ros/component_params.h"
#include "sowing_robot/ros/msg_checks.h"

namespace sowing_robot {

ReferenceGenerator::ReferenceGenerator(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  const std::string type = p.get("type", "line");
  const double v_r = p.get("line/v_r", 1.0), row_y = p.get("line/y", 3.0), x0 = p.get("line/x0", 0.0);
  path_spacing_ = p.get("path_spacing", path_spacing_);
  std::string error = type == "line" ? "" : "type = '" + type + "' must be 'line'";
  if (error.empty())
    error = core::firstError({core::checkRange("line/v_r", v_r, 0.0, 10.0, "m/s"),
                              core::allFinite(row_y, x0) ? "" : "line/y and line/x0 must be finite",
                              core::checkPositive("path_spacing", path_spacing_, "m")});
  requireValid(p, error);
  source_ = std::make_unique<core::LineReference>(v_r, row_y, x0);
  ROS_INFO("reference_generator: line x = %.3f + %.3f t, y = %.3f", x0, v_r, row_y);
  ref_pub_ = nh.advertise<ReferenceState>("reference", kLockstepQueue);
  path_pub_ = nh.advertise<nav_msgs::Path>("reference_path", 1, true);
  path_.header.frame_id = "odom";
  odom_sub_ = nh.subscribe("odom", 50, &ReferenceGenerator::odomCallback, this, ros::TransportHints().tcpNoDelay());
}

void ReferenceGenerator::odomCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  const ros::Time& stamp = msg->header.stamp;
  if (any_ && stamp <= ref_.header.stamp) {  // a repeat (or an old state): answer with what we said
    if (stamp == ref_.header.stamp) ref_pub_.publish(ref_);
    return;
  }
  const core::Reference r = source_->next(stamp.toSec());
  ref_.header.stamp = stamp;
  ref_.header.frame_id = "odom";
  ref_.x = r.pose.x;
  ref_.y = r.pose.y;
  ref_.theta = r.pose.theta;
  ref_.v = r.v;
  ref_.omega = r.omega;
  ref_.v_dot = r.v_dot;
  ref_.omega_dot = r.omega_dot;
  ref_.tool_down = r.tool_down;
  ref_pub_.publish(ref_);
  any_ = true;

  const bool far = path_.poses.empty() || std::hypot(r.pose.x - path_.poses.back().pose.position.x,
                                                     r.pose.y - path_.poses.back().pose.position.y) >= path_spacing_;
  if (far) {
    geometry_msgs::PoseStamped p;
    p.header = ref_.header;
    p.pose.position.x = r.pose.x;
    p.pose.position.y = r.pose.y;
    p.pose.orientation.z = std::sin(0.5 * r.pose.theta);
    p.pose.orientation.w = std::cos(0.5 * r.pose.theta);
    if (path_.poses.size() >= 20000) path_.poses.erase(path_.poses.begin(), path_.poses.begin() + 10000);
    path_.poses.push_back(p);
    path_.header.stamp = stamp;
    path_pub_.publish(path_);
  }
}

}  // namespace sowing_robot
