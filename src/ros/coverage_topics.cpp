#include "sowing_robot/ros/coverage_topics.h"

#include <cmath>

#include "sowing_robot/ros/common/markers.h"
#include "sowing_robot/ros/common/msg_checks.h"

namespace sowing_robot {

namespace {

using visualization_msgs::Marker;
using visualization_msgs::MarkerArray;

struct Style {
  float r, g, b, a;
  double width;  ///< line width [m]: seen at the scale of a whole field (about 5 px per metre for 1 ha)
  double z;      ///< drawn above the ground's grid, the later layers above the earlier
};

// Colours against rviz's dark soil background (rviz/coverage.rviz): the boundary pale, the voids blue as water, the
// headlands amber, the swaths green; the route (an rviz Path display) and the seeds (yellow) go over them.
constexpr Style kBoundary{0.95f, 0.95f, 0.85f, 1.0f, 0.35, 0.02};
constexpr Style kVoid{0.25f, 0.55f, 1.0f, 1.0f, 0.35, 0.02};
constexpr Style kHeadland{1.0f, 0.6f, 0.1f, 0.9f, 0.15, 0.03};
constexpr Style kSwath{0.3f, 0.8f, 0.3f, 0.7f, 0.12, 0.03};

Marker lineMarker(const std::string& frame, const std::string& ns, int id, int type, const Style& s) {
  Marker m = rvizMarker(frame, ns, id, {type, s.r, s.g, s.b, s.a, s.width});
  m.pose.position.z = s.z;
  return m;
}

geometry_msgs::Point point(const Eigen::Vector2d& p) {
  geometry_msgs::Point q;
  q.x = p.x();
  q.y = p.y();
  return q;
}

/// A ring as a closed LINE_STRIP (the planner's rings are open: the first point is not repeated).
Marker ringMarker(const core::Ring& ring, const std::string& frame, const std::string& ns, int id, const Style& s) {
  Marker m = lineMarker(frame, ns, id, Marker::LINE_STRIP, s);
  for (const Eigen::Vector2d& p : ring) m.points.push_back(point(p));
  if (ring.size() > 1 && ring.front() != ring.back()) m.points.push_back(point(ring.front()));
  return m;
}

/// A DELETEALL first, so a re-published plan replaces the old one whole in rviz.
MarkerArray cleared(const std::string& frame) {
  MarkerArray out;
  out.markers.push_back(deleteAllMarker(frame));
  return out;
}

}  // namespace

MarkerArray coverageFieldMarkers(const core::CoveragePlan& plan, const std::string& frame) {
  MarkerArray out = cleared(frame);
  for (std::size_t i = 0; i < plan.field.size(); ++i)
    out.markers.push_back(i == 0 ? ringMarker(plan.field[i], frame, "boundary", 0, kBoundary)
                                 : ringMarker(plan.field[i], frame, "voids", static_cast<int>(i - 1), kVoid));
  return out;
}

MarkerArray coverageHeadlandMarkers(const core::CoveragePlan& plan, const std::string& frame) {
  MarkerArray out = cleared(frame);
  for (std::size_t i = 0; i < plan.headland_rings.size(); ++i)
    out.markers.push_back(ringMarker(plan.headland_rings[i], frame, "headlands", static_cast<int>(i), kHeadland));
  return out;
}

MarkerArray coverageSwathMarkers(const core::CoveragePlan& plan, const std::string& frame) {
  MarkerArray out = cleared(frame);
  Marker m = lineMarker(frame, "swaths", 0, Marker::LINE_LIST, kSwath);
  for (const core::Swath& s : plan.swaths) {
    m.points.push_back(point(s.a));
    m.points.push_back(point(s.b));
  }
  out.markers.push_back(m);
  return out;
}

nav_msgs::Path coverageRoutePath(const core::CoveragePath& route, const std::string& frame, const ros::Time& stamp) {
  nav_msgs::Path out;
  out.header.frame_id = frame;
  out.header.stamp = stamp;
  const std::size_t n = route.points.size();
  double heading = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i + 1 < n) {
      const Eigen::Vector2d d = route.points[i + 1] - route.points[i];
      if (d.squaredNorm() > 0.0) heading = std::atan2(d.y(), d.x());  // the last point keeps its segment's heading
    }
    geometry_msgs::PoseStamped p;
    p.header = out.header;
    p.pose.position = point(route.points[i]);
    p.pose.orientation = yawQuaternion(heading);
    out.poses.push_back(p);
  }
  return out;
}

CoverageTopics::CoverageTopics(ros::NodeHandle nh, const core::CoveragePlan& plan, const core::CoveragePath& route,
                               const std::string& frame) {
  field_pub_ = nh.advertise<MarkerArray>("coverage/field", 1, true);
  headlands_pub_ = nh.advertise<MarkerArray>("coverage/headlands", 1, true);
  swaths_pub_ = nh.advertise<MarkerArray>("coverage/swaths", 1, true);
  route_pub_ = nh.advertise<nav_msgs::Path>("coverage/route", 1, true);
  field_pub_.publish(coverageFieldMarkers(plan, frame));
  headlands_pub_.publish(coverageHeadlandMarkers(plan, frame));
  swaths_pub_.publish(coverageSwathMarkers(plan, frame));
  route_pub_.publish(coverageRoutePath(route, frame, ros::Time::now()));
}

}  // namespace sowing_robot
