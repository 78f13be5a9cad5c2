// The main() of a callback-driven node: the wrapper class does the work, ros::spin() serves its callbacks.
#pragma once

#include <ros/ros.h>

namespace sowing_robot {

template <typename Wrapper>
int runCallbackNode(int argc, char** argv, const char* name) {
  ros::init(argc, argv, name);
  ros::NodeHandle nh, pnh("~");
  Wrapper node(nh, pnh);
  ros::spin();
  return 0;
}

}  // namespace sowing_robot
