// run_monitor: accumulates the tracking-error metrics of a run (Tables 5.5/5.6) and prints them when
// the scenario ends. The errors are the TRUE ones: ground_truth against the reference of the same stamp
// (core::worldErrors, as kinematic_controller computes its tracking_error from its feedback, so with
// feedback:=ground_truth the numbers are the same bit for bit), whatever the controllers are fed;
// optionally writes them to YAML and ends the launch (headless runs). With a recorder
// (`~recorder`: its recorded_until topic) it ends the launch only once the recorder has written the
// run's last period, or, after `~recorder_timeout` wall seconds without that, with a failure (exit 3).
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <std_msgs/Time.h>

#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "sowing_robot/ReferenceState.h"
#include "sowing_robot/core/simulation/metrics.h"
#include "sowing_robot/ros/common/node_failure.h"
#include "sowing_robot/ros/common/ready_roster.h"
#include "sowing_robot/ros/common/stamp_pair.h"

namespace sowing_robot {

class RunMonitor {
 public:
  RunMonitor(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~RunMonitor();

  /// The exit code the run ended with: 0, or kGaveUp when the recorder never confirmed the end.
  int exitCode() const;

 private:
  void truthCallback(const nav_msgs::Odometry::ConstPtr& msg);
  void referenceCallback(const ReferenceState::ConstPtr& msg);
  /// The true error of the state and reference paired for one stamp.
  void addPair();
  void recordedCallback(const std_msgs::Time::ConstPtr& msg);
  void waitForRecorder();
  void finish();
  void endRun();

  double duration_ = 25.0;
  double recorder_timeout_ = 60.0;  // [s wall] for the recorder to catch up after the last period
  std::string output_, label_, recorder_topic_;
  bool exit_at_end_ = false, done_ = false;
  core::MetricsAccumulator metrics_;
  ros::Time last_;
  ros::NodeHandle pnh_;
  // The reference is sent ahead of the state, but the plant does not wait for this node: under load its
  // states can arrive seconds ahead of their references, so both streams hold a whole lookahead's worth.
  ListenerPair<nav_msgs::Odometry, ReferenceState> inputs_;
  std::int64_t expected_samples_ = 0;  // lockstep: every period of the run, both ends included (0: not checked)
  ros::Subscriber truth_sub_, ref_sub_, recorder_sub_;

  // The wait for the recorder: a thread of its own with a bounded wait, not a ros::WallTimer: roscpp's
  // timer thread queues a callback while holding its timer lock, and InlineCallbackQueue runs it right
  // there, where re-scheduling the timer takes that lock again (a deadlock, seen).
  mutable std::mutex wait_mutex_;
  std::condition_variable recorded_;
  ros::Time recorded_until_;             // under wait_mutex_
  bool waiting_ = false, stop_ = false;  // under wait_mutex_
  std::optional<NodeFailure> failure_;   // under wait_mutex_
  std::thread waiter_;
  ReadyAnnouncer ready_;  // plant_sim waits for it before step 0
};

}  // namespace sowing_robot
