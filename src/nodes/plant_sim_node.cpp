// Standalone plant_sim node: the wrapper class does the work.
#include <ros/ros.h>

#include "sowing_robot/ros/plant_sim.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "plant_sim");
  ros::NodeHandle nh, pnh("~");
  sowing_robot::PlantSim node(nh, pnh);
  node.run();
  return 0;
}
