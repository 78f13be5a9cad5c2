// Standalone state_estimator node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/state_estimator.h"

namespace {
const char* const kUsage =
    SOWING_NODE_USAGE("state_estimator",
                      "The state estimator (feedback:=fused): an EKF over wheel odometry, yaw rate and position fix\n"
                      "(odom, imu, fix) -> odometry/filtered.\n");
}  // namespace

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::StateEstimator>(argc, argv, "state_estimator", kUsage);
}
