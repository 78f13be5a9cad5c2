// Standalone kinematic_controller node: the wrapper class does the work.
#include <ros/ros.h>

#include "sowing_robot/ros/kinematic_controller.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "kinematic_controller");
  ros::NodeHandle nh, pnh("~");
  sowing_robot::KinematicController node(nh, pnh);
  ros::spin();
  return 0;
}
