#include "sowing_robot/ros/plant_sim/contacts.h"

#include <geometry_msgs/PolygonStamped.h>

#include <stdexcept>

namespace sowing_robot {

PlantContacts::PlantContacts(ros::NodeHandle nh, const core::Footprint& footprint, const std::string& odom_frame,
                             const std::string& base_frame)
    : monitor_(footprint, {}), odom_frame_(odom_frame) {
  contact_pub_ = nh.advertise<Contact>("contacts", 100, true);
  footprint_pub_ = nh.advertise<geometry_msgs::PolygonStamped>("footprint", 1, true);
  geometry_msgs::PolygonStamped polygon;
  polygon.header.frame_id = base_frame;
  for (const Eigen::Vector2d& v : footprint.vertices()) {
    geometry_msgs::Point32 p;
    p.x = static_cast<float>(v.x());
    p.y = static_cast<float>(v.y());
    polygon.polygon.points.push_back(p);
  }
  footprint_pub_.publish(polygon);
  plan_sub_ = nh.subscribe("plan", 1, &PlantContacts::planCallback, this);
}

void PlantContacts::planCallback(const FieldPlan::ConstPtr& plan) {
  std::vector<core::Obstacle> obstacles(std::min(plan->obstacle_centres.size(), plan->obstacle_radii.size()));
  for (std::size_t i = 0; i < obstacles.size(); ++i)
    obstacles[i] = {plan->obstacle_centres[i].x, plan->obstacle_centres[i].y, plan->obstacle_radii[i]};
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    monitor_.setObstacles(obstacles);
    obstacles_ = obstacles;
  } catch (const std::invalid_argument& e) {
    ROS_WARN("plant_sim: contact check keeps its obstacles: the plan's are invalid (%s)", e.what());
  }
}

void PlantContacts::update(double t, const core::Pose2D& pose) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!monitor_.update(t, pose)) return;  // nothing started or ended (almost every step)
  const auto& events = monitor_.events();
  for (std::size_t i = 0; i < events.size(); ++i) {
    const core::ContactEvent& e = events[i];
    const bool started = i >= reported_.size(), ended = !started && reported_[i] && !e.ongoing;
    if (!started && !ended) continue;
    publish(e);
    if (started)
      ROS_WARN(
          "plant_sim: contact with obstacle %zu at t=%.3f s: the body overlaps it (the plant does not stop "
          "the robot)",
          e.obstacle, e.start);
    else
      ROS_WARN("plant_sim: contact with obstacle %zu ended at t=%.3f s, %.3f m deep at most", e.obstacle, e.end,
               e.max_depth);
  }
  reported_.resize(events.size());
  for (std::size_t i = 0; i < events.size(); ++i) reported_[i] = events[i].ongoing;
}

void PlantContacts::publish(const core::ContactEvent& e) {
  Contact m;
  m.header.frame_id = odom_frame_;
  m.header.stamp.fromSec(e.ongoing ? e.start : e.end);
  m.obstacle = static_cast<std::uint32_t>(e.obstacle);
  if (e.obstacle < obstacles_.size()) {
    m.centre.x = obstacles_[e.obstacle].x;
    m.centre.y = obstacles_[e.obstacle].y;
    m.radius = obstacles_[e.obstacle].radius;
  }
  m.start = e.start;
  m.end = e.end;
  m.max_depth = e.max_depth;
  m.ongoing = e.ongoing;
  m.contacts = static_cast<std::uint32_t>(monitor_.contactCount());
  m.min_clearance = monitor_.minClearance();
  contact_pub_.publish(m);
}

std::string PlantContacts::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  monitor_.finish();
  return monitor_.report();
}

}  // namespace sowing_robot
