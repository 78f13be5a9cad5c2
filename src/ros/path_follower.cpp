#include "sowing_robot/ros/path_follower.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/msg_checks.h"

namespace sowing_robot {

namespace {
constexpr double kProgressPeriod = 0.1;   // [s] of simulated time between periodic ~progress messages
constexpr double kPlannedSpacing = 0.05;  // [m] between planned_path poses
// at most this many planned_path poses: a whole field's route (10 km) at 5 cm would be a 16 MB latched message, in
// rviz and in every lean bag; paths up to 1 km keep the 5 cm
constexpr int kMaxPlannedPoses = 20000;
constexpr std::size_t kMaxSent = 100000;  // references remembered for states not yet come (100 s at 1 kHz)
}  // namespace

std::string loadPathPoints(ParamReader& p, std::vector<Eigen::Vector2d>& out) {
  out.clear();
  const std::string key = "path/points";
  p.allow(key);
  XmlRpc::XmlRpcValue list;
  if (!p.handle().getParam(key, list)) return "";
  const std::string full = p.handle().resolveName(key);
  if (list.getType() != XmlRpc::XmlRpcValue::TypeArray) return "parameter " + full + " must be a list of [x, y]";
  for (int i = 0; i < list.size(); ++i) {
    double x, y;
    if (list[i].getType() != XmlRpc::XmlRpcValue::TypeArray || list[i].size() != 2 || !xmlNumber(list[i][0], x) ||
        !xmlNumber(list[i][1], y))
      return full + "[" + std::to_string(i) + "] must be a pair of numbers [x, y]";
    if (!std::isfinite(x) || !std::isfinite(y)) return full + "[" + std::to_string(i) + "] is not finite";
    out.emplace_back(x, y);
  }
  if (out.empty()) return "parameter " + full + " is an empty list (leave it out to wait for a path on `path`)";
  return "";
}

PathFollower::PathFollower(ros::NodeHandle nh, ros::NodeHandle pnh, core::PathReference& source, std::string frame,
                           const char* origin)
    : source_(source), frame_(std::move(frame)) {
  progress_pub_ = pnh.advertise<PathProgress>("progress", 1, true);
  planned_pub_ = nh.advertise<nav_msgs::Path>("planned_path", 1, true);
  progress_.header.frame_id = frame_;
  if (source_.hasPath()) {
    planChanged(origin);
  } else {
    progress_.status = PathProgress::NO_PATH;
    progress_pub_.publish(progress_);
    ROS_INFO("reference_generator: no path yet: holding the start until one comes on %s",
             nh.resolveName("path").c_str());
  }
  path_sub_ = nh.subscribe("path", 1, &PathFollower::pathCallback, this);
  feedback_sub_ =
      nh.subscribe("feedback", 100, &PathFollower::feedbackCallback, this, ros::TransportHints().tcpNoDelay());
}

void PathFollower::pathCallback(const nav_msgs::Path::ConstPtr& msg) {
  const std::string& frame = msg->header.frame_id;
  if (!frame.empty() && frame != frame_ && frame != "/" + frame_) {
    ROS_WARN("reference_generator: dropping path: it is in frame '%s', not %s", frame.c_str(), frame_.c_str());
    return;
  }
  std::vector<Eigen::Vector2d> points;
  for (const geometry_msgs::PoseStamped& p : msg->poses) points.emplace_back(p.pose.position.x, p.pose.position.y);
  try {
    source_.setPath(points);
  } catch (const std::invalid_argument& e) {
    ROS_WARN("reference_generator: dropping path of %zu poses: %s; the path in force is kept", points.size(), e.what());
    return;
  }
  planChanged(progress_.path == 0 ? "path" : "path (a replacement)");
}

void PathFollower::planChanged(const char* why) {
  const core::PathPlan& plan = source_.plan();
  ++progress_.path;
  progress_.status = PathProgress::FOLLOWING;
  progress_.length = plan.length();
  progress_.distance_done = progress_.cross_track = progress_.max_cross_track = progress_.rms_cross_track = 0.0;
  progress_.distance_left = plan.length();
  progress_.time_to_go = plan.duration();
  progress_.goal_distance = (plan.vertices().front() - plan.goal()).norm();
  s_robot_ = sum_sq_ = 0.0;
  samples_ = 0;
  ROS_INFO(
      "reference_generator: path %u from %s, from t = %.3f s: %zu points after joining and simplifying, %.3f m in "
      "%.3f s, %d corner(s) rounded (cut by <= %.3f m), %d turn(s) in place",
      progress_.path, why, source_.planStart(), plan.vertices().size(), plan.length(), plan.duration(), plan.fillets(),
      plan.maxCornerCut(), plan.pivots());
  nav_msgs::Path out;
  out.header.frame_id = frame_;
  out.header.stamp = ros::Time::now();
  const int n = std::clamp(static_cast<int>(std::ceil(plan.length() / kPlannedSpacing)), 1, kMaxPlannedPoses);
  for (int i = 0; i <= n; ++i) {
    const core::Reference r = plan.at(plan.timeAt(plan.length() * i / n));
    geometry_msgs::PoseStamped p;
    p.header = out.header;
    p.pose.position.x = r.pose.x;
    p.pose.position.y = r.pose.y;
    p.pose.orientation = yawQuaternion(r.pose.theta);
    out.poses.push_back(p);
  }
  planned_pub_.publish(out);
  publishProgress(ros::Time::now());
}

void PathFollower::referenceSent(std::int64_t stamp_ns) {
  if (sent_.size() >= kMaxSent) sent_.pop_front();
  sent_.push_back(Sent{stamp_ns, source_.lastTime(), progress_.path});
}

void PathFollower::feedbackCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  // The reference of this stamp (realtime: the last one sent at or before it).
  const std::int64_t stamp = static_cast<std::int64_t>(msg->header.stamp.toNSec());
  while (sent_.size() > 1 && sent_[1].stamp_ns <= stamp) sent_.pop_front();
  if (sent_.empty() || sent_.front().stamp_ns > stamp) return;
  const Sent ref = sent_.front();
  const Eigen::Vector2d p(msg->pose.pose.position.x, msg->pose.pose.position.y);
  // A state under the path before (or before any), or with no position to measure: not this path's progress.
  if (ref.path != progress_.path || progress_.path == 0 || !p.allFinite()) return;
  const double t = msg->header.stamp.toSec(), tau = ref.source_time - source_.planStart();
  const core::PathPlan& plan = source_.plan();
  // Search near the robot's last progress and the reference's, so a path that passes by itself is not skipped.
  const double s_ref = plan.arcLengthAt(tau);
  const core::PathPlan::Projection at =
      plan.project(p, std::max(0.0, s_robot_ - 0.5), std::min(plan.length(), std::max(s_ref, s_robot_) + 1.0));
  s_robot_ = at.s;
  ++samples_;
  sum_sq_ += at.cross_track * at.cross_track;
  progress_.cross_track = at.cross_track;
  progress_.max_cross_track = std::max(progress_.max_cross_track, std::fabs(at.cross_track));
  progress_.rms_cross_track = std::sqrt(sum_sq_ / samples_);
  progress_.distance_done = at.s;
  progress_.distance_left = plan.length() - at.s;
  progress_.time_to_go = std::max(0.0, plan.duration() - plan.timeAt(at.s));
  progress_.goal_distance = (p - plan.goal()).norm();
  const std::uint8_t before = progress_.status;
  if (before != PathProgress::REACHED)
    progress_.status = tau < plan.duration()                                        ? PathProgress::FOLLOWING
                       : progress_.goal_distance <= source_.params().goal_tolerance ? PathProgress::REACHED
                                                                                    : PathProgress::SETTLING;
  if (progress_.status == PathProgress::SETTLING && before == PathProgress::FOLLOWING)
    ROS_INFO(
        "reference_generator: path %u: the reference stopped at the goal at t = %.3f s; the robot is %.4f m from it "
        "(path/goal_tolerance %.3f m), cross-track max %.4f m",
        progress_.path, t, progress_.goal_distance, source_.params().goal_tolerance, progress_.max_cross_track);
  if (progress_.status == PathProgress::REACHED && before != PathProgress::REACHED) {
    const double yaw = 2.0 * std::atan2(msg->pose.pose.orientation.z, msg->pose.pose.orientation.w);
    ROS_INFO(
        "reference_generator: path %u: goal reached at t = %.3f s: %.4f m from the goal, heading error %.4f rad; "
        "cross-track max %.4f m, RMS %.4f m over %.3f m",
        progress_.path, t, progress_.goal_distance, core::wrapAngle(plan.at(plan.duration()).pose.theta - yaw),
        progress_.max_cross_track, progress_.rms_cross_track, plan.length());
  }
  if (progress_.status != before || t >= next_publish_) publishProgress(msg->header.stamp);
}

void PathFollower::publishProgress(const ros::Time& stamp) {
  progress_.header.stamp = stamp;
  progress_pub_.publish(progress_);
  next_publish_ = stamp.toSec() + kProgressPeriod;
}

}  // namespace sowing_robot
