// seed_map: a bag's seed record (the seed drill's `seeds/record`) as a CSV table and/or a GeoJSON map. The work is
// the seed_map library's (include/sowing_robot/seed_map/); this main parses, reads, writes and says so in one line.
#include <cstdio>
#include <string>
#include <vector>

#include "sowing_robot/cli/usage.h"
#include "sowing_robot/seed_map/bag_seeds.h"
#include "sowing_robot/seed_map/seed_map.h"

int main(int argc, char** argv) {
  namespace sm = sowing_robot::seed_map;
  sowing_robot::cli::exitOnHelp(argc, argv, sm::kUsage);
  sm::Options options;
  std::string error = sm::parseArguments(std::vector<std::string>(argv + 1, argv + argc), options);
  if (!error.empty()) {
    std::fprintf(stderr, "seed_map: %s\n", error.c_str());
    return sowing_robot::cli::kUsageExit;
  }
  std::vector<sowing_robot::core::Seed> seeds;
  std::string topic;
  error = sm::readBagSeeds(options.bag, options.topic, seeds, topic);
  if (error.empty()) error = sm::writeMaps(options, seeds);
  if (!error.empty()) {
    std::fprintf(stderr, "seed_map: %s\n", error.c_str());
    return 1;
  }
  std::string written = options.csv;
  if (!options.geojson.empty()) written += (written.empty() ? "" : ", ") + options.geojson;
  std::printf("seed_map: %zu seeds from %s (t = %.3f .. %.3f s) -> %s\n", seeds.size(), topic.c_str(), seeds.front().t,
              seeds.back().t, written.c_str());
  return 0;
}
