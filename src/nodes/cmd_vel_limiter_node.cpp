// Standalone cmd_vel_limiter node: the wrapper class does the work.
#include "sowing_robot/ros/cmd_vel_limiter.h"
#include "sowing_robot/ros/common/node_main.h"

namespace {
const char* const kUsage = SOWING_NODE_USAGE(
    "cmd_vel_limiter",
    "Velocity mode (sim.launch input:=cmd_vel): velocity commands on cmd_vel (geometry_msgs/Twist) or\n"
    "cmd_vel_stamped (TwistStamped), through a velocity / acceleration / jerk limiter and cmd_vel_timeout,\n"
    "to the inner loop's desired_velocity, one per state on feedback.\n");
}  // namespace

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::CmdVelLimiter>(argc, argv, "cmd_vel_limiter", kUsage);
}
