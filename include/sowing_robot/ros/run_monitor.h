// run_monitor: accumulates the tracking-error metrics of a run (Tables 5.5/5.6) and prints them when
// the scenario ends; optionally writes them to YAML and ends the launch (headless runs).
#pragma once

#include <ros/ros.h>

#include <string>

#include "sowing_robot/TrackingError.h"
#include "sowing_robot/core/metrics.h"

namespace sowing_robot {

class RunMonitor {
 public:
  RunMonitor(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  void errorCallback(const TrackingError::ConstPtr& msg);
  void finish();

  double duration_ = 25.0;
  std::string output_, label_;
  bool exit_at_end_ = false, done_ = false;
  core::MetricsAccumulator metrics_;
  ros::Time last_;
  ros::Subscriber sub_;
};


}  // namespace sowing_robot
