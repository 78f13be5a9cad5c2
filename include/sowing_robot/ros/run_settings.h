// Settings of the whole run that every node reads the same way (not one node's private parameters).
#pragma once

#include <ros/node_handle.h>

#include <string>

#include "sowing_robot/ros/param_reader.h"

namespace sowing_robot {

/// `run/mode` (relative to the node's public handle, so a namespaced run has its own): true for
/// "lockstep", false for "realtime" (the default). In lockstep a node waits for the input paired with a
/// state's stamp however long it takes: a timeout on simulated time has no meaning there, since simulated
/// time advances only when the loop does. Any other value refuses to start.
inline bool lockstepRun(const ros::NodeHandle& nh) {
  std::string mode = "realtime";
  if (nh.hasParam("run/mode") && !nh.getParam("run/mode", mode)) refuseToStart("run/mode must be a string");
  if (mode != "realtime" && mode != "lockstep")
    refuseToStart("run/mode = '" + mode + "' must be 'realtime' or 'lockstep'");
  return mode == "lockstep";
}

}  // namespace sowing_robot
