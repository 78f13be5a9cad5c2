// Standalone run_monitor node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/run_monitor.h"

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::RunMonitor>(argc, argv, "run_monitor");
}
