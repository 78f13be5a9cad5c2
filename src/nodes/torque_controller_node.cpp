// Standalone torque_controller node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/torque_controller.h"

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::TorqueController>(argc, argv, "torque_controller");
}
