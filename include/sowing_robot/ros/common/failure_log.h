// How a program's main (or a nodelet's onInit) reports a NodeFailure: as one FATAL line naming the node,
// the last word of that node. Shared so that every sowing_robot node words it the same way
// (bad_param.test and the sim runner look for "refusing to start").
#pragma once

#include <ros/console.h>

#include <string>

#include "sowing_robot/ros/common/node_failure.h"

namespace sowing_robot {

/// "<who>: refusing to start: <reason>" for a bad parameter, "<who>: <reason>" for the others.
inline std::string failureLine(const std::string& who, const NodeFailure& failure) {
  return who + (failure.code() == ExitCode::kBadParameter ? ": refusing to start: " : ": ") + failure.what();
}

inline void logFailure(const std::string& who, const NodeFailure& failure) {
  ROS_FATAL("%s", failureLine(who, failure).c_str());
}

}  // namespace sowing_robot
