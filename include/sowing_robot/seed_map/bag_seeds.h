// The seed record of a bag: the seed drill's sowing_robot/Seed messages (`seeds/record`, recorded by sim.launch
// record:=true) read back as core::Seed (the conversion: ros/common/seed_message.h).
#pragma once

#include <string>
#include <vector>

#include "sowing_robot/core/planning/seeding.h"

namespace sowing_robot {
namespace seed_map {

/// The seeds of `path` in bag order (time order), from `topic` or ("") from the bag's one topic of type
/// sowing_robot/Seed; `used_topic` names it. "" or the one line why not: the bag cannot be read (missing, corrupt,
/// unindexed), it holds no seed, or seeds on several topics without `topic` to choose one.
std::string readBagSeeds(const std::string& path, const std::string& topic, std::vector<core::Seed>& seeds,
                         std::string& used_topic);

}  // namespace seed_map
}  // namespace sowing_robot
