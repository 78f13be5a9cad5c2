#include "sowing_robot/ros/seed_drill.h"

#include <std_msgs/Float64MultiArray.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <cstdio>

#include "sowing_robot/ros/component_params.h"
#include "sowing_robot/ros/msg_checks.h"
#include "sowing_robot/ros/urdf_params.h"

namespace sowing_robot {

namespace {
constexpr std::size_t kChunk = 1000;  // seeds per marker: rviz keeps every chunk, we resend only the last
}

SeedDrillNode::SeedDrillNode(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  core::SeedingParams sp;
  sp.spacing = p.get("spacing", sp.spacing);
  sp.tolerance = p.get("tolerance", sp.tolerance);
  sp.detour_margin = p.get("detour_margin", sp.detour_margin);
  sp.engage_distance = p.get("engage_distance", sp.engage_distance);
  const std::string tool_link = p.get("tool_link", "tool_link");
  p.allow("robot_description");
  std::string error = sp.validate();

  // The tool point comes from the URDF, the rows and obstacles from the reference generator's own
  // parameters: the drill scores the sown line against exactly what was planned.
  std::string key, xml;
  if (error.empty()) {
    if (!pnh.searchParam("robot_description", key) || !pnh.getParam(key, xml))
      error = "parameter robot_description (the URDF) is not set";
    else
      error = linkPositionFromUrdf(xml, tool_link, tool_x_, tool_y_);
  }
  ParamReader ref(ros::NodeHandle("/reference_generator"));
  const std::string type = ref.get("type", "line");
  std::vector<core::RowSegment> rows;
  std::vector<core::Obstacle> obstacles;
  double influence = 0.0;
  if (error.empty() && type == "field") {
    const core::FieldParams field = loadFieldParams(ref, error);
    if (error.empty()) error = loadObstacles(ref, "obstacles", obstacles);
    if (error.empty()) {
      rows = core::rowsOf(field);
      influence = field.potential.influence_distance;
    }
  } else if (error.empty()) {
    const double x0 = ref.get("line/x0", 0.0), y = ref.get("line/y", 3.0);
    rows = {{Eigen::Vector2d(x0, y), Eigen::Vector2d(x0 + 1e5, y)}};  // the thesis line, open-ended
  }
  requireValid(p, error);
  drill_ = std::make_unique<core::SeedDrill>(sp, rows, obstacles, influence);
  ROS_INFO("seed_drill: tool point (%.3f, %.3f) m in base_link, a seed every %.3f m, %zu row(s), %zu obstacle(s)",
           tool_x_, tool_y_, sp.spacing, rows.size(), obstacles.size());

  chunk_.header.frame_id = "odom";
  chunk_.ns = "seeds";
  chunk_.type = visualization_msgs::Marker::SPHERE_LIST;
  chunk_.action = visualization_msgs::Marker::ADD;
  chunk_.pose.orientation.w = 1.0;
  chunk_.scale.x = chunk_.scale.y = chunk_.scale.z = 0.04;
  chunk_.color.r = 0.95f;
  chunk_.color.g = 0.85f;
  chunk_.color.b = 0.3f;
  chunk_.color.a = 1.0f;
  seeds_pub_ = nh.advertise<visualization_msgs::MarkerArray>("seeds", 10);
  report_pub_ = nh.advertise<std_msgs::Float64MultiArray>("seed_report", 1, true);
  const auto hints = ros::TransportHints().tcpNoDelay();
  odom_sub_ = nh.subscribe("odom", kLockstepQueue, &SeedDrillNode::odomCallback, this, hints);
  ref_sub_ = nh.subscribe("reference", kLockstepQueue, &SeedDrillNode::referenceCallback, this, hints);
  publishReport();
}

SeedDrillNode::~SeedDrillNode() {
  // stdout, not rosconsole: at shutdown the logger may already be gone.
  if (drill_) std::printf("seed_drill: %s\n", drill_->report().c_str());
  std::fflush(stdout);
}

void SeedDrillNode::odomCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  if (!odomIsFinite(*msg)) return;
  if (inputs_.setFirst(*msg)) update(inputs_.first(), inputs_.second().tool_down);
}

void SeedDrillNode::referenceCallback(const ReferenceState::ConstPtr& msg) {
  if (inputs_.setSecond(*msg)) update(inputs_.first(), inputs_.second().tool_down);
}

void SeedDrillNode::update(const nav_msgs::Odometry& odom, bool tool_down) {
  const core::Pose2D pose = poseOf(odom);
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  const Eigen::Vector2d tool(pose.x + c * tool_x_ - s * tool_y_, pose.y + s * tool_x_ + c * tool_y_);
  Eigen::Vector2d seed;
  if (!drill_->update(tool, tool_down, seed)) return;
  if (chunk_.points.size() >= kChunk) {
    chunk_.points.clear();
    ++chunk_id_;
  }
  geometry_msgs::Point pt;
  pt.x = seed.x();
  pt.y = seed.y();
  chunk_.points.push_back(pt);
  chunk_.id = chunk_id_;
  chunk_.header.stamp = odom.header.stamp;
  visualization_msgs::MarkerArray out;
  out.markers.push_back(chunk_);
  seeds_pub_.publish(out);
  if (++seeds_ % 50 == 0) publishReport();
}

void SeedDrillNode::publishReport() {
  std_msgs::Float64MultiArray r;
  const core::SeedStats &rows = drill_->onRows(), &det = drill_->detours();
  r.layout.dim.resize(1);
  r.layout.dim[0].label = "rows_count,rows_max,rows_rms,rows_fraction_over,detour_count,detour_max,detour_rms";
  r.layout.dim[0].size = 7;
  r.layout.dim[0].stride = 7;
  r.data = {static_cast<double>(rows.count), rows.max, rows.rms, rows.fraction_over,
            static_cast<double>(det.count), det.max, det.rms};
  report_pub_.publish(r);
}

}  // namespace sowing_robot
