// Standalone run_monitor node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/run_monitor.h"

namespace {
const char* const kUsage = SOWING_NODE_USAGE(
    "run_monitor",
    "Scores a run: the thesis metrics from ground_truth against the reference, printed once at the end\n"
    "(and written as YAML with metrics_output); headless, it ends the run.\n");
}  // namespace

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::RunMonitor>(argc, argv, "run_monitor", kUsage);
}
