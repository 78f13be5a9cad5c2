// Standalone kinematic_controller node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/kinematic_controller.h"

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::KinematicController>(argc, argv, "kinematic_controller");
}
