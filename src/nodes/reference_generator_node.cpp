// Standalone reference_generator node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/reference_generator.h"

namespace {
const char* const kUsage = SOWING_NODE_USAGE(
    "reference_generator",
    "The reference: the row (or line, sine) to follow, with the potential field and planned detours around\n"
    "obstacles, sent `lookahead` ahead on `reference`; also the field markers and the plan.\n");
}  // namespace

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::ReferenceGenerator>(argc, argv, "reference_generator", kUsage);
}
