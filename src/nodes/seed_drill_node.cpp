// Standalone seed_drill node: the wrapper class does the work.
#include "sowing_robot/ros/common/node_main.h"
#include "sowing_robot/ros/seed_drill.h"

namespace {
const char* const kUsage =
    SOWING_NODE_USAGE("seed_drill",
                      "The seed drill: drops seeds at the tool point of the true pose while the tool is down on a row\n"
                      "(`seeds`, `seed_report`) and records each seed, true and believed position (`seeds/record`).\n");
}  // namespace

int main(int argc, char** argv) {
  return sowing_robot::runCallbackNode<sowing_robot::SeedDrillNode>(argc, argv, "seed_drill", kUsage);
}
