// Standalone kinematic_controller node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/kinematic_controller.h"

namespace {
const char* const kUsage = SOWING_NODE_USAGE(
    "kinematic_controller",
    "The outer loop: the kinematic controller (outer:= kanayama, pure_pursuit, rpp) turns the feedback pose\n"
    "and the reference into desired wheel velocities (desired_velocity) and the tracking error.\n");
}  // namespace

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::KinematicController>(argc, argv, "kinematic_controller", kUsage);
}
