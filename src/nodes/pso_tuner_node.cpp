// Standalone pso_tuner node: the wrapper class does the work, then the process exits (offline tool).
#include <ros/ros.h>

#include "sowing_robot/ros/pso_tuner.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "pso_tuner");
  ros::NodeHandle nh, pnh("~");
  sowing_robot::PsoTuner tuner(nh, pnh);
  const int code = tuner.run();
  ros::shutdown();
  return code;
}
