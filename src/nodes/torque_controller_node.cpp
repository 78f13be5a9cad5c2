// Standalone torque_controller node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/torque_controller.h"

namespace {
const char* const kUsage = SOWING_NODE_USAGE(
    "torque_controller",
    "The inner loop: the torque controller (inner:= atsmc, tsmc, pid) turns the desired velocities and the\n"
    "feedback into wheel torques (wheel_torque).\n");
}  // namespace

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::TorqueController>(argc, argv, "torque_controller", kUsage);
}
