// A seed as the seed drill records it (sowing_robot/Seed on `seeds/record`) and back: the one conversion the seed
// drill node publishes with and the seed maps read a bag's record with.
#pragma once

#include <ros/time.h>

#include <string>

#include "sowing_robot/Seed.h"
#include "sowing_robot/core/planning/seeding.h"

namespace sowing_robot {

/// The record of `seed`, stamped `stamp` in `frame` (the stamp is given, not rebuilt from seed.t, so the node's
/// record carries the state's stamp to the nanosecond).
inline Seed seedMessage(const core::Seed& seed, const ros::Time& stamp, const std::string& frame) {
  Seed m;
  m.header.stamp = stamp;
  m.header.frame_id = frame;
  m.position.x = seed.truth.x();
  m.position.y = seed.truth.y();
  m.believed.x = seed.believed.x();
  m.believed.y = seed.believed.y();
  m.row = seed.row;
  m.depth = seed.depth;
  m.detour = seed.detour;
  return m;
}

/// The seed of a record, its time the stamp's seconds.
inline core::Seed seedOf(const Seed& msg) {
  core::Seed s;
  s.t = msg.header.stamp.toSec();
  s.truth = {msg.position.x, msg.position.y};
  s.believed = {msg.believed.x, msg.believed.y};
  s.row = msg.row;
  s.depth = msg.depth;
  s.detour = msg.detour;
  return s;
}

}  // namespace sowing_robot
