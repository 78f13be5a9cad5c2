// Standalone plant_sim node: the wrapper class does the work; this main decides how the process ends.
// A run that cannot go on (NodeFailure: the state diverged, or lockstep gave up) is logged as the node's
// one FATAL line and becomes its exit code (2, 3).
#include <ros/ros.h>

#include "sowing_robot/cli/usage.h"
#include "sowing_robot/ros/common/failure_log.h"
#include "sowing_robot/ros/common/node_failure.h"
#include "sowing_robot/ros/common/param_reader.h"
#include "sowing_robot/ros/plant_sim/plant_sim.h"

namespace {
const char* const kUsage = SOWING_NODE_USAGE(
    "plant_sim",
    "The simulated robot: the plant (no-slip or traction) driven by wheel_torque, its sensors (odom, imu,\n"
    "fix), contacts with the obstacles, and /clock (wall-paced in realtime, by the loop in lockstep).\n");
}  // namespace

int main(int argc, char** argv) {
  sowing_robot::cli::checkNodeArguments(argc, argv, "plant_sim", kUsage);
  ros::init(argc, argv, "plant_sim");
  ros::NodeHandle nh, pnh("~");
  try {
    sowing_robot::PlantSim node(nh, pnh);
    ros::AsyncSpinner spinner(1);  // the global queue; run() serves the wheel_torque queue itself
    spinner.start();
    node.run();
    if (!node.exitAtEnd()) ros::waitForShutdown();
  } catch (const sowing_robot::NodeFailure& failure) {
    sowing_robot::logFailure(ros::this_node::getName(), failure);
    // roscpp's threads still run (a torque callback may be waiting): shut it down before the end.
    sowing_robot::exitProcess(failure.exitCode());
  }
  return 0;
}
