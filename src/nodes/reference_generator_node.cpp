// Standalone reference_generator node: the wrapper class does the work.
#include <ros/ros.h>

#include "sowing_robot/ros/reference_generator.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "reference_generator");
  ros::NodeHandle nh, pnh("~");
  sowing_robot::ReferenceGenerator node(nh, pnh);
  ros::spin();
  return 0;
}
