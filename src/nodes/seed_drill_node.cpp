// Standalone seed_drill node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/seed_drill.h"

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::SeedDrillNode>(argc, argv, "seed_drill");
}
