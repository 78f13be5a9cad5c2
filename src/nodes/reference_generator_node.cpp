// Standalone reference_generator node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/reference_generator.h"

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::ReferenceGenerator>(argc, argv, "reference_generator");
}
