// fleet_monitor (fleet.launch): the one owner of /clock in a fleet, and its safety check.
// Each robot's nodes run under robot_<i>/ with their own lockstep loop, and its plant_sim's /clock is remapped
// to robot_<i>/clock (so the robot's nodes keep its time). The robots do not touch, so each loop repeats bit for
// bit on its own. This node publishes /clock as the slowest robot's time (rviz, robot_state_publisher and the
// static frames follow it), compares the robots' ground_truth positions stamp by stamp
// (core/simulation/fleet_proximity.h), warns when two come closer than safety_distance, publishes
// fleet/proximity (FleetProximity, latched, every simulated second and at each encounter), and at the end
// prints the fleet's summary; headless (exit_at_end) it ends the launch once every robot's clock has reached
// run/duration and every robot's run_monitor has printed its metrics and gone, or, with a FATAL line and exit 3,
// as soon as a robot's plant_sim is gone before its end (the slowest robot's clock would never move again).
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "sowing_robot/FleetProximity.h"
#include "sowing_robot/core/simulation/fleet_proximity.h"
#include "sowing_robot/ros/common/node_failure.h"

namespace sowing_robot {

class FleetMonitor {
 public:
  FleetMonitor(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~FleetMonitor();
  /// 0, or 3 (gave up) when a robot's plant_sim ended before run/duration (the run was ended for it).
  int exitCode() const { return failure_ ? failure_->exitCode() : 0; }

 private:
  void clockCallback(int robot, const rosgraph_msgs::Clock::ConstPtr& msg);
  void truthCallback(int robot, const nav_msgs::Odometry::ConstPtr& msg);
  /// fleet/proximity from what has been compared (under mutex_).
  void publishReport();
  /// The end of a headless run: polled from a thread of its own (not a WallTimer: see run_monitor.h).
  void watchForEnd();
  std::string name(int robot) const { return "robot_" + std::to_string(robot); }

  std::mutex mutex_;  // the callbacks and the end watcher
  std::optional<core::FleetProximity> proximity_;
  double safety_distance_ = 0.0;
  std::vector<ros::Time> clocks_;  // each robot's latest /clock
  ros::Time published_;            // the /clock last sent
  double next_report_ = 0.0;       // [s] simulated
  double duration_ = 0.0;
  ros::Publisher clock_pub_, report_pub_;
  std::vector<ros::Subscriber> subs_;
  std::atomic<bool> stop_{false};
  std::set<std::string> plants_seen_;   // the robots whose plant_sim the watcher has seen registered
  std::optional<NodeFailure> failure_;  // set by the watcher before it requests the shutdown
  std::thread watcher_;
};

}  // namespace sowing_robot
