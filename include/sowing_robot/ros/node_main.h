// The main() of a callback-driven node: the wrapper class does the work; its callbacks run inline on
// roscpp's threads (InlineCallbackQueue), so a message costs no hand-over to a spinner thread.
#pragma once

#include <ros/ros.h>

#include <memory>
#include <mutex>

#include "sowing_robot/ros/inline_callback_queue.h"

namespace sowing_robot {

template <typename Wrapper>
int runCallbackNode(int argc, char** argv, const char* name) {
  ros::init(argc, argv, name);
  InlineCallbackQueue queue;
  ros::NodeHandle nh, pnh("~");
  nh.setCallbackQueue(&queue);
  pnh.setCallbackQueue(&queue);
  std::unique_ptr<Wrapper> node;
  {
    // A callback (a latched message on a new connection) may come before the constructor has finished.
    std::lock_guard<std::recursive_mutex> lock(queue.mutex());
    node = std::make_unique<Wrapper>(nh, pnh);
  }
  ros::waitForShutdown();  // returns once roscpp's threads have ended: no callback can be running
  node.reset();
  return 0;
}

}  // namespace sowing_robot
