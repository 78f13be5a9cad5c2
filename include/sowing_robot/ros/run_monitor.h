// run_monitor: accumulates the tracking-error metrics of a run (Tables 5.5/5.6) and prints them when
// the scenario ends; optionally writes them to YAML and ends the launch (headless runs). With a recorder
// (`~recorder`: its recorded_until topic) it ends the launch only once the recorder has written the
// run's last period, or, after `~recorder_timeout` wall seconds without that, with a failure (exit 3).
#pragma once

#include <ros/ros.h>
#include <std_msgs/Time.h>

#include <optional>
#include <string>

#include "sowing_robot/TrackingError.h"
#include "sowing_robot/core/metrics.h"
#include "sowing_robot/ros/node_failure.h"

namespace sowing_robot {

class RunMonitor {
 public:
  RunMonitor(ros::NodeHandle nh, ros::NodeHandle pnh);

  /// The exit code the run ended with: 0, or kGaveUp when the recorder never confirmed the end.
  int exitCode() const { return failure_ ? failure_->exitCode() : 0; }

 private:
  void errorCallback(const TrackingError::ConstPtr& msg);
  void recordedCallback(const std_msgs::Time::ConstPtr& msg);
  void recorderTimedOut(const ros::WallTimerEvent&);
  void finish();
  void endRun();

  double duration_ = 25.0;
  double recorder_timeout_ = 60.0;  // [s wall] for the recorder to catch up after the last period
  std::string output_, label_, recorder_topic_;
  bool exit_at_end_ = false, done_ = false, waiting_for_recorder_ = false;
  core::MetricsAccumulator metrics_;
  ros::Time last_, recorded_until_;
  ros::WallTime wait_start_;
  std::optional<NodeFailure> failure_;
  ros::NodeHandle nh_, pnh_;
  ros::Subscriber sub_, recorder_sub_;
  ros::WallTimer recorder_timer_;
};

}  // namespace sowing_robot
