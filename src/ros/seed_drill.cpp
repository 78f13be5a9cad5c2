#include "sowing_robot/ros/seed_drill.h"

#include <std_msgs/Float64MultiArray.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <cstdio>

#include "sowing_robot/core/simulation/lockstep.h"
#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/markers.h"
#include "sowing_robot/ros/common/msg_checks.h"
#include "sowing_robot/ros/common/seed_message.h"
#include "sowing_robot/ros/common/urdf_params.h"

namespace sowing_robot {

namespace {
constexpr std::size_t kChunk = 1000;  // seeds per marker: rviz keeps every chunk, we resend only the last
}

SeedDrillNode::SeedDrillNode(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  const core::RunSettings run = loadRunSettings(nh, p);
  loadTable(p, core::SeedDrillSettings::table(), settings_);
  p.allow("robot_description");
  std::string error = settings_.validate();
  // The tool point comes from the URDF; the rows and obstacles from the reference generator's `plan`.
  std::string key, xml;
  if (error.empty()) {
    if (!pnh.searchParam("robot_description", key) || !pnh.getParam(key, xml))
      error = "parameter robot_description (the URDF) is not set";
    else
      error = linkPositionFromUrdf(xml, settings_.tool_link, tool_x_, tool_y_);
  }
  requireValid(p, error);
  if (run.duration > 0.0) end_ns_ = core::lockstepLastStep(run.duration, run.periodNs()) * run.periodNs();
  logSettings("seed_drill", core::SeedDrillSettings::table(), settings_);
  ROS_INFO("seed_drill: tool point (%.3f, %.3f) m in base_link; waiting for the plan", tool_x_, tool_y_);

  const double size = settings_.marker_size;
  chunk_ = rvizMarker(run.odom_frame, "seeds", 0,
                      {visualization_msgs::Marker::SPHERE_LIST, 0.95f, 0.85f, 0.3f, 1.0f, size, size, size});
  seeds_pub_ = nh.advertise<visualization_msgs::MarkerArray>("seeds", kLockstepQueue);
  record_pub_ = nh.advertise<Seed>("seeds/record", kLockstepQueue);
  odom_frame_ = run.odom_frame;
  report_pub_ = nh.advertise<std_msgs::Float64MultiArray>("seed_report", 100, true);
  // Subscribed here, not from the plan's callback: a subscription made from a callback of the shared
  // nodelet thread while the plant publishes its state hung a nodelet run (1 in ~10 under load). States that
  // come before the first plan (latched: it comes at once) are not scored (the robot is still at rest).
  plan_sub_ = nh.subscribe("plan", 1, &SeedDrillNode::planCallback, this);
  const auto hints = ros::TransportHints().tcpNoDelay();
  // The true pose (the seeds fall where the robot really is, whatever the controllers believe).
  odom_sub_ = nh.subscribe("ground_truth", kLockstepQueue, &SeedDrillNode::odomCallback, this, hints);
  ref_sub_ = nh.subscribe("reference", kLockstepQueue, &SeedDrillNode::referenceCallback, this, hints);
  if (settings_.follow_hitch)
    torque_sub_ = nh.subscribe("wheel_torque", kLockstepQueue, &SeedDrillNode::torqueCallback, this, hints);
  // The believed pose: what the controllers are fed (the launch remaps their `feedback`, and this node's, to
  // ground_truth, odom or odometry/filtered). Paired by stamp, so a lockstep run records the same seeds.
  const std::string fed = nh.resolveName("feedback");
  believed_is_truth_ = fed == nh.resolveName("ground_truth") || fed == nh.resolveName("feedback", false);
  if (!believed_is_truth_)
    believed_sub_ = nh.subscribe("feedback", kLockstepQueue, &SeedDrillNode::believedCallback, this, hints);
  ROS_INFO("seed_drill: believed tool position from %s", believed_is_truth_ ? "the true pose" : fed.c_str());
  ready_ = ReadyAnnouncer(nh, pnh, run.lockstep,
                          {odom_sub_, ref_sub_, torque_sub_, believed_sub_});  // last: all subscribed (ready_roster.h)
}

void SeedDrillNode::planCallback(const FieldPlan::ConstPtr& msg) {
  const std::size_t n = std::min(msg->row_starts.size(), msg->row_ends.size());
  std::vector<core::RowSegment> rows(n);
  for (std::size_t i = 0; i < n; ++i)
    rows[i] = {Eigen::Vector2d(msg->row_starts[i].x, msg->row_starts[i].y),
               Eigen::Vector2d(msg->row_ends[i].x, msg->row_ends[i].y)};
  std::vector<core::Obstacle> obstacles(std::min(msg->obstacle_centres.size(), msg->obstacle_radii.size()));
  for (std::size_t i = 0; i < obstacles.size(); ++i)
    obstacles[i] = {msg->obstacle_centres[i].x, msg->obstacle_centres[i].y, msg->obstacle_radii[i]};
  if (drill_) {
    drill_->setPlan(std::move(rows), std::move(obstacles), msg->influence_distance);
    ROS_INFO("seed_drill: plan changed: %zu row(s), %zu obstacle(s)", n, msg->obstacle_radii.size());
    return;
  }
  drill_ = std::make_unique<core::SeedDrill>(settings_.seeding, std::move(rows), std::move(obstacles),
                                             msg->influence_distance);
  ROS_INFO("seed_drill: plan of %zu row(s), %zu obstacle(s): sowing", n, msg->obstacle_radii.size());
  publishReport(msg->header.stamp);
}

SeedDrillNode::~SeedDrillNode() {
  // stdout, not rosconsole: at shutdown the logger may already be gone.
  if (drill_) std::printf("seed_drill: %s\n", drill_->report().c_str());
  std::fflush(stdout);
}

void SeedDrillNode::odomCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  if (!drill_ || !odomIsFinite(*msg)) return;
  if (inputs_.setFirst(*msg)) paired(inputs_.first(), inputs_.second().tool_down);
}

void SeedDrillNode::referenceCallback(const ReferenceState::ConstPtr& msg) {
  if (!drill_) return;
  if (inputs_.setSecond(*msg)) paired(inputs_.first(), inputs_.second().tool_down);
}

void SeedDrillNode::paired(const nav_msgs::Odometry& odom, bool tool_down) {
  if (!settings_.follow_hitch) {
    update(odom, {tool_down, false, seedDepth(0.0)});
    return;
  }
  if (hitch_inputs_.setFirst({odom.header, odom, tool_down})) updateHitchPair();
}

void SeedDrillNode::torqueCallback(const WheelTorque::ConstPtr& msg) {
  if (!drill_) return;
  if (hitch_inputs_.setSecond(*msg)) updateHitchPair();
}

void SeedDrillNode::updateHitchPair() {
  const WheelTorque& torque = hitch_inputs_.second();
  update(hitch_inputs_.first().odom,
         {hitch_inputs_.first().tool_down, static_cast<bool>(torque.tool_raised), seedDepth(torque.tool_depth)});
}

void SeedDrillNode::update(const nav_msgs::Odometry& odom, const ToolState& tool) {
  if (believed_is_truth_) {
    sow(odom, odom, tool);
    return;
  }
  if (believed_inputs_.setFirst({odom.header, odom, tool}))
    sow(believed_inputs_.first().truth, believed_inputs_.second(), believed_inputs_.first().tool);
}

void SeedDrillNode::believedCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  // Kept even before the plan: the state of the same stamp may come after it (another connection).
  if (believed_inputs_.setSecond(*msg))
    sow(believed_inputs_.first().truth, believed_inputs_.second(), believed_inputs_.first().tool);
}

Eigen::Vector2d SeedDrillNode::toolPoint(const nav_msgs::Odometry& odom) const {
  const core::Pose2D pose = poseOf(odom);
  double s, c;
  s = std::sin(pose.theta);
  c = std::cos(pose.theta);
  return Eigen::Vector2d(pose.x + c * tool_x_ - s * tool_y_, pose.y + s * tool_x_ + c * tool_y_);
}

double SeedDrillNode::seedDepth(double sent_depth) const {
  if (sent_depth > 0.0) return sent_depth;
  const core::SeedingParams& p = settings_.seeding;
  return 0.5 * (p.depth_min + p.depth_max);
}

void SeedDrillNode::sow(const nav_msgs::Odometry& truth, const nav_msgs::Odometry& believed, const ToolState& tool) {
  const ros::Time& stamp = truth.header.stamp;
  core::Seed seed;
  if (drill_->drop(stamp.toSec(), toolPoint(truth), toolPoint(believed), tool.down, tool.held_up, tool.depth, seed))
    addSeed(seed, stamp);
  if (!final_sent_ && end_ns_ >= 0 && static_cast<std::int64_t>(stamp.toNSec()) >= end_ns_) {
    final_sent_ = true;
    publishReport(stamp);
  }
}

void SeedDrillNode::addSeed(const core::Seed& seed, const ros::Time& stamp) {
  record_pub_.publish(seedMessage(seed, stamp, odom_frame_));
  if (chunk_.points.size() >= kChunk) {
    chunk_.points.clear();
    ++chunk_id_;
  }
  geometry_msgs::Point pt;
  pt.x = seed.truth.x();
  pt.y = seed.truth.y();
  chunk_.points.push_back(pt);
  chunk_.id = chunk_id_;
  chunk_.header.stamp = stamp;
  visualization_msgs::MarkerArray out;
  out.markers.push_back(chunk_);
  seeds_pub_.publish(out);
  if (++seeds_ % 50 == 0) publishReport(stamp);
}

void SeedDrillNode::publishReport(const ros::Time& stamp) {
  std_msgs::Float64MultiArray r;
  const core::SeedStats &rows = drill_->onRows(), &det = drill_->detours();
  r.layout.dim.resize(1);
  // the stamp last (message_stamp.h): a deterministic bag records the report at it
  r.layout.dim[0].label = "rows_count,rows_max,rows_rms,rows_fraction_over,detour_count,detour_max,detour_rms,stamp";
  r.layout.dim[0].size = 8;
  r.layout.dim[0].stride = 8;
  r.data = {static_cast<double>(rows.count), rows.max, rows.rms, rows.fraction_over,
            static_cast<double>(det.count),  det.max,  det.rms,  stamp.toSec()};
  report_pub_.publish(r);
}

}  // namespace sowing_robot
