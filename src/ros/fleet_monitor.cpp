#include "sowing_robot/ros/fleet_monitor.h"

#include <ros/master.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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
  if (s.yield) {
    yield_ = true;
    decision_ns_ = std::llround(s.decision_period * 1e9);
    if (decision_ns_ % run.periodNs() != 0)
      throw badParameter(pnh.resolveName("decision_period") + " must be a multiple of the control period");
    yield_distance_ = s.yield_distance;
    yield_hysteresis_ = s.yield_hysteresis;
    statuses_.resize(static_cast<std::size_t>(s.robots));
    yields_.assign(static_cast<std::size_t>(s.robots), 0);
    held_.assign(static_cast<std::size_t>(s.robots), 0);
    last_hold_.assign(static_cast<std::size_t>(s.robots), false);
    verdict_pub_ = nh.advertise<FleetVerdict>("/fleet/verdict", 1, true);
    for (int i = 0; i < s.robots; ++i)
      subs_.push_back(nh.subscribe<FleetRobotStatus>(
          name(i) + "/fleet/status", 100000, [this, i](const FleetRobotStatus::ConstPtr& m) { statusCallback(i, m); },
          ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
    ROS_INFO(
        "fleet_monitor: yield on: every %.3f s of simulated time, the later robot of a pair closer than %.3f m holds "
        "(until farther than %.3f m); verdicts on %s",
        s.decision_period, yield_distance_, yield_distance_ + yield_hysteresis_, verdict_pub_.getTopic().c_str());
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

void FleetMonitor::statusCallback(int robot, const FleetRobotStatus::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::int64_t stamp = static_cast<std::int64_t>(msg->header.stamp.toNSec());
  if (stamp <= decided_ns_ || stamp % decision_ns_ != 0) return;  // a repeat, or off the decision grid
  statuses_[static_cast<std::size_t>(robot)][stamp] = *msg;
  decide();
}

void FleetMonitor::decide() {
  for (;;) {
    const std::int64_t next = decided_ns_ < 0 ? 0 : decided_ns_ + decision_ns_;
    std::vector<core::FleetYield::State> states;
    std::vector<int> ranks;
    for (auto& robot : statuses_) {
      const auto it = robot.find(next);
      if (it == robot.end()) return;  // not every robot's state at `next` yet
      core::FleetYield::State st;
      st.x = it->second.x;
      st.y = it->second.y;
      st.progress = it->second.progress;
      st.started = it->second.started;
      states.push_back(st);
      ranks.push_back(it->second.rank);
    }
    FleetVerdict verdict;
    verdict.header.stamp.fromNSec(static_cast<std::uint64_t>(next));
    try {
      if (!fleet_yield_) fleet_yield_.emplace(ranks, yield_distance_, yield_hysteresis_);
      const std::vector<bool>& holds = fleet_yield_->update(states);
      verdict.hold.assign(holds.begin(), holds.end());
    } catch (const std::invalid_argument& e) {
      // No verdict is no answer: the robots would wait for ever. Nobody holds, and the run says why.
      ROS_ERROR_THROTTLE(1.0, "fleet_monitor: no yield decision at t = %.3f s: %s; nobody holds", 1e-9 * next,
                         e.what());
      verdict.hold.assign(statuses_.size(), false);
    }
    for (std::size_t i = 0; i < verdict.hold.size(); ++i) {
      // A robot waiting for its start or finished stands anyway: its hold is neither a yield nor held time.
      const bool driving = states[i].started && states[i].progress < 1.0;
      if (verdict.hold[i] && !last_hold_[i] && driving) {
        ++yields_[i];
        ROS_INFO("fleet_monitor: %s yields at t = %.3f s (a robot of higher priority within %.3f m)",
                 name(static_cast<int>(i)).c_str(), 1e-9 * next, yield_distance_);
      } else if (!verdict.hold[i] && last_hold_[i] && driving) {
        ROS_INFO("fleet_monitor: %s goes on at t = %.3f s", name(static_cast<int>(i)).c_str(), 1e-9 * next);
      }
      if (verdict.hold[i] && driving) ++held_[i];
      last_hold_[i] = verdict.hold[i] && driving;
      statuses_[i].erase(statuses_[i].begin(), statuses_[i].upper_bound(next));
    }
    verdict_pub_.publish(verdict);
    decided_ns_ = next;
  }
}

std::string FleetMonitor::yieldSummary() const {
  std::string out = "yield: decided to t = " + std::to_string(1e-9 * std::max<std::int64_t>(0, decided_ns_)) + " s;";
  for (std::size_t i = 0; i < yields_.size(); ++i) {
    char text[120];
    std::snprintf(text, sizeof text, " %s %d yield(s), held %.1f s;", name(static_cast<int>(i)).c_str(), yields_[i],
                  core::secondsFromNanos(held_[i] * decision_ns_));
    out += text;
  }
  return out;
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
      // As nodelets (nodelets:=true) the robot's nodes live in its manager: their loaders (--no-bond) outlive it.
      const bool manager = running.count("/" + robot + "/sowing_manager") > 0;
      if (manager) managers_seen_.insert(robot);
      const bool manager_gone = managers_seen_.count(robot) > 0 && !manager;
      monitors = monitors || (running.count("/" + robot + "/run_monitor") > 0 && !manager_gone);
      const bool plant = running.count("/" + robot + "/plant_sim") > 0 && !manager_gone;
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
    if (yield_) ROS_INFO("fleet_monitor: %s", yieldSummary().c_str());
    ros::requestShutdown();
    return;
  }
}

}  // namespace sowing_robot
