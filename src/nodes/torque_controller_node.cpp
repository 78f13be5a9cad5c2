// Standalone torque_controller node: the wrapper class does the work.
#include <ros/ros.h>

#include "sowing_robot/ros/torque_controller.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "torque_controller");
  ros::NodeHandle nh, pnh("~");
  sowing_robot::TorqueController node(nh, pnh);
  ros::spin();
  return 0;
}
