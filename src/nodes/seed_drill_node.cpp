// Standalone seed_drill node: the wrapper class does the work.
#include <ros/ros.h>

#include "sowing_robot/ros/seed_drill.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "seed_drill");
  ros::NodeHandle nh, pnh("~");
  sowing_robot::SeedDrillNode node(nh, pnh);
  ros::spin();
  return 0;
}
