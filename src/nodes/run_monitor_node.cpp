// Standalone run_monitor node: the wrapper class does the work.
#include <ros/ros.h>

#include "sowing_robot/ros/run_monitor.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "run_monitor");
  ros::NodeHandle nh, pnh("~");
  sowing_robot::RunMonitor node(nh, pnh);
  ros::spin();
  return 0;
}
