// Standalone fleet_monitor node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/fleet_monitor.h"

namespace {
const char* const kUsage = SOWING_NODE_USAGE(
    "fleet_monitor",
    "fleet.launch: owns /clock (the slowest robot's), compares the robots' positions by stamp, warns of\n"
    "encounters closer than safety_distance (fleet/proximity), and ends a headless fleet run.\n");
}  // namespace

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::FleetMonitor>(argc, argv, "fleet_monitor", kUsage);
}
