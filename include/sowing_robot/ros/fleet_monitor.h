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
// With yield (a fleet sharing a field): the run-time yield's referee. On every decision stamp t (decision_period) it
// waits for every robot's fleet/status of t (its true position at t, its progress, its plan rank), applies
// core::FleetYield (the later robot of a pair within yield_distance holds, never every robot of a group) and publishes
// the verdict for t on /fleet/verdict (latched); each robot's reference sends nothing past t until it has it. So the
// verdicts, and every robot's run, depend on the robots' states at the decision stamps only. It counts each robot's
// yields and the time it was held, and prints them at the end.
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "sowing_robot/FleetProximity.h"
#include "sowing_robot/FleetRobotStatus.h"
#include "sowing_robot/FleetVerdict.h"
#include "sowing_robot/core/simulation/fleet_proximity.h"
#include "sowing_robot/core/simulation/fleet_yield.h"
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
  /// yield: a robot's state on a decision stamp; decides every stamp all robots have reported (under mutex_).
  void statusCallback(int robot, const FleetRobotStatus::ConstPtr& msg);
  void decide();
  /// The yield's figures, one line (under mutex_).
  std::string yieldSummary() const;
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
  std::set<std::string> managers_seen_;  // the robots whose nodelet manager the watcher has seen (nodelets:=true)
  std::set<std::string> plants_seen_;    // the robots whose plant_sim the watcher has seen registered
  std::optional<NodeFailure> failure_;   // set by the watcher before it requests the shutdown
  std::thread watcher_;

  // yield
  bool yield_ = false;
  std::int64_t decision_ns_ = 0, decided_ns_ = -1;  // the last decision stamp decided [ns]; -1: none
  double yield_distance_ = 0.0, yield_hysteresis_ = 0.0;
  std::optional<core::FleetYield> fleet_yield_;
  std::vector<std::map<std::int64_t, FleetRobotStatus>> statuses_;  // per robot, by stamp, not yet decided
  std::vector<int> yields_;                                         // per robot: holds begun
  std::vector<std::int64_t> held_;                                  // per robot: decision periods held
  std::vector<bool> last_hold_;                                     // per robot: the last verdict
  ros::Publisher verdict_pub_;
};

}  // namespace sowing_robot
