// Standalone state_estimator node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/state_estimator.h"

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::StateEstimator>(argc, argv, "state_estimator");
}
