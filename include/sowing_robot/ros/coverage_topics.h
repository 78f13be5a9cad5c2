// The coverage plan on topics (reference_generator, type coverage), as nav2's opennav_coverage shows its plan: latched,
// in the frame the plan's points are in (run/odom_frame: the field file's local frame is the odom frame), names
// relative to the node's namespace (a fleet's robot shows its own).
//   coverage/field      (visualization_msgs/MarkerArray) the boundary (ns "boundary") and each void (ns "voids"), one
//                       LINE_STRIP per ring, closed
//   coverage/headlands  (visualization_msgs/MarkerArray) each headland pass's centre ring (ns "headlands"), one
//                       LINE_STRIP per ring, in the order they are driven
//   coverage/swaths     (visualization_msgs/MarkerArray) one LINE_LIST (ns "swaths"): a pair of points per swath, its
//                       centre line from where it is entered to where it is left, in route order
//   coverage/route      (nav_msgs/Path) the route driven from its start (ros/coverage_route.h: the route's own start,
//                       or a fleet robot's share after its start pose): the swaths, turns and headland loops; each
//                       pose heads along the segment it starts
// geometry_msgs/PolygonStamped holds one ring (a field with voids has several), hence the markers for display. The
// messages are built by the functions below, so a test needs no master to check them.
#pragma once

#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include <string>

#include "sowing_robot/core/planning/coverage_planner.h"

namespace sowing_robot {

visualization_msgs::MarkerArray coverageFieldMarkers(const core::CoveragePlan& plan, const std::string& frame);
visualization_msgs::MarkerArray coverageHeadlandMarkers(const core::CoveragePlan& plan, const std::string& frame);
visualization_msgs::MarkerArray coverageSwathMarkers(const core::CoveragePlan& plan, const std::string& frame);
nav_msgs::Path coverageRoutePath(const core::CoveragePath& route, const std::string& frame, const ros::Time& stamp);

/// Advertises the four topics (latched) on nh and publishes the plan once.
class CoverageTopics {
 public:
  CoverageTopics(ros::NodeHandle nh, const core::CoveragePlan& plan, const core::CoveragePath& route,
                 const std::string& frame);

 private:
  ros::Publisher field_pub_, headlands_pub_, swaths_pub_, route_pub_;
};

}  // namespace sowing_robot
