#include "sowing_robot/ros/fleet_monitor.h"

#include <ros/master.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/failure_log.h"

namespace sowing_robot {

namespace {
constexpr double kReportPeriod = 1.0;  // [s] of simulated time between periodic fleet/proximity messages
}  // namespace

FleetMonitor::FleetMonitor(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  core::FleetMonitorSettings s;
  loadTable(p, core::FleetMonitorSettings::table(), s);
  const core::RunSettings run = loadRunSettings(nh, p);
  requireValid(p, p.error().empty() ? s.validate() : "");
  duration_ = run.duration;
  safety_distance_ = s.safety_distance;
  proximity_.emplace(s.robots, s.safety_distance);  // validated: does not throw
  clocks_.assign(static_cast<std::size_t>(s.robots), ros::Time(0));
  clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  report_pub_ = nh.advertise<FleetProximity>("fleet/proximity", 1, true);
  for (int i = 0; i < s.robots; ++i) {
    subs_.push_back(nh.subscribe<rosgraph_msgs::Clock>(
        name(i) + "/clock", 10, [this, i](const rosgraph_msgs::Clock::ConstPtr& m) { clockCallback(i, m); }));
    // A robot's states may run far ahead of another's: the queue holds them until they can be compared.
    subs_.push_back(nh.subscribe<nav_msgs::Odometry>(
        name(i) + "/ground_truth", 200000, [this, i](const nav_msgs::Odometry::ConstPtr& m) { truthCallback(i, m); },
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  ROS_INFO("fleet_monitor: %d robots (robot_0 ... robot_%d), safety_distance %.3f m; /clock is the slowest robot's",
           s.robots, s.robots - 1, s.safety_distance);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    publishReport();
  }
  if (s.exit_at_end && duration_ > 0.0) watcher_ = std::thread([this] { watchForEnd(); });
}

FleetMonitor::~FleetMonitor() {
  stop_ = true;
  if (watcher_.joinable()) watcher_.join();
}

void FleetMonitor::clockCallback(int robot, const rosgraph_msgs::Clock::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  ros::Time& own = clocks_[static_cast<std::size_t>(robot)];
  own = std::max(own, msg->clock);
  const ros::Time slowest = *std::min_element(clocks_.begin(), clocks_.end());
  if (slowest <= published_) return;
  published_ = slowest;
  rosgraph_msgs::Clock out;
  out.clock = slowest;
  clock_pub_.publish(out);
}

void FleetMonitor::truthCallback(int robot, const nav_msgs::Odometry::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto begun = proximity_->add(robot, static_cast<std::int64_t>(msg->header.stamp.toNSec()),
                                     msg->pose.pose.position.x, msg->pose.pose.position.y);
  for (const auto& e : begun)
    ROS_WARN("fleet_monitor: %s and %s closer than %.3f m (safety_distance) at t = %.3f s: %.3f m", name(e.a).c_str(),
             name(e.b).c_str(), safety_distance_, e.begin, e.min_distance);
  const double t = core::secondsFromNanos(std::max<std::int64_t>(0, proximity_->lastCompared()));
  if (!begun.empty() || t >= next_report_) publishReport();
}

void FleetMonitor::publishReport() {
  FleetProximity r;
  r.header.stamp.fromNSec(static_cast<std::uint64_t>(std::max<std::int64_t>(0, proximity_->lastCompared())));
  r.safety_distance = safety_distance_;
  r.closest = proximity_->closest();
  if (proximity_->closestA() >= 0) {
    r.closest_pair = name(proximity_->closestA()) + " " + name(proximity_->closestB());
    r.closest_time = proximity_->closestTime();
  }
  r.encounters = static_cast<std::uint32_t>(proximity_->encounters().size());
  for (const auto& e : proximity_->encounters())
    if (e.open) r.within.push_back(name(e.a) + " " + name(e.b));
  report_pub_.publish(r);
  next_report_ = r.header.stamp.toSec() + kReportPeriod;
}

void FleetMonitor::watchForEnd() {
  // Every robot's clock at the end, then every robot's run_monitor gone (it prints its metrics first). A robot
  // whose plant_sim is gone before its end would hold the fleet's clock for ever: the run ends with it.
  while (!stop_ && ros::ok()) {
    ros::WallDuration(0.2).sleep();
    std::vector<std::string> nodes;
    if (!ros::master::getNodes(nodes)) continue;
    const std::set<std::string> running(nodes.begin(), nodes.end());
    bool at_end = true, monitors = false;
    for (std::size_t i = 0; i < clocks_.size(); ++i) {
      const std::string robot = name(static_cast<int>(i));
      double clock;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        clock = clocks_[i].toSec();
      }
      const bool done = clock >= duration_ - 1e-9;
      at_end = at_end && done;
      monitors = monitors || running.count("/" + robot + "/run_monitor") > 0;
      const bool plant = running.count("/" + robot + "/plant_sim") > 0;
      if (plant) plants_seen_.insert(robot);  // (one that has not started yet is not gone)
      if (!done && !plant && plants_seen_.count(robot)) {
        char text[160];
        std::snprintf(text, sizeof text, "%s's plant_sim ended at t = %.3f s, before run/duration: the fleet run ends",
                      robot.c_str(), clock);
        failure_.emplace(ExitCode::kGaveUp, text);
        logFailure(ros::this_node::getName(), *failure_);
        ros::requestShutdown();
        return;
      }
    }
    if (!at_end || monitors) continue;
    std::lock_guard<std::mutex> lock(mutex_);
    publishReport();
    ROS_INFO(
        "fleet_monitor: %zu robots to t = %.3f s, %ld stamps compared (%zu states left unpaired); closest approach "
        "%.3f m (%s at t = %.3f s); %zu encounter(s) closer than %.3f m",
        clocks_.size(), published_.toSec(), static_cast<long>(proximity_->compared()), proximity_->pending(),
        proximity_->closest(),
        proximity_->closestA() < 0 ? "-"
                                   : (name(proximity_->closestA()) + " and " + name(proximity_->closestB())).c_str(),
        proximity_->closestTime(), proximity_->encounters().size(), safety_distance_);
    ros::requestShutdown();
    return;
  }
}

}  // namespace sowing_robot
