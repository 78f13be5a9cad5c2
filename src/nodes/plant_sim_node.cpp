// Standalone plant_sim node: the wrapper class does the work.
#include <ros/ros.h>

#include "sowing_robot/ros/plant_sim.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "plant_sim");
  ros::NodeHandle nh, pnh("~");
  sowing_robot::PlantSim node(nh, pnh);
  ros::AsyncSpinner spinner(1);  // the global queue; run() serves the wheel_torque queue itself
  spinner.start();
  node.run();
  if (!node.exitAtEnd()) ros::waitForShutdown();
  return 0;
}
