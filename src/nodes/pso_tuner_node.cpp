// Standalone pso_tuner node: the wrapper class does the work, then the process exits (offline tool).
// A bad parameter (NodeFailure) becomes one FATAL line and exit 1.
#include <ros/ros.h>

#include "sowing_robot/cli/usage.h"
#include "sowing_robot/ros/common/failure_log.h"
#include "sowing_robot/ros/common/param_reader.h"
#include "sowing_robot/ros/pso_tuner.h"

namespace {
const char* const kUsage = SOWING_NODE_USAGE(
    "pso_tuner",
    "Offline PSO tuning of the controller gains on the in-process closed loop (roslaunch sowing_robot\n"
    "tune.launch); writes the gains YAML and publishes pso/progress, then exits.\n");
}  // namespace

int main(int argc, char** argv) {
  sowing_robot::cli::checkNodeArguments(argc, argv, "pso_tuner", kUsage);
  ros::init(argc, argv, "pso_tuner");
  ros::NodeHandle nh, pnh("~");
  int code = 0;
  try {
    sowing_robot::PsoTuner tuner(nh, pnh);
    code = tuner.run();
  } catch (const sowing_robot::NodeFailure& failure) {
    sowing_robot::logFailure(ros::this_node::getName(), failure);
    sowing_robot::exitProcess(failure.exitCode());
  }
  ros::shutdown();
  return code;
}
