// The main() of a callback-driven node: the wrapper class does the work; its callbacks run inline on
// roscpp's threads (InlineCallbackQueue), so a message costs no hand-over to a spinner thread.
// This is where a NodeFailure thrown while the wrapper starts (a bad parameter) becomes the node's one
// FATAL line and its exit code; the wrapper itself never ends the process.
#pragma once

#include <ros/ros.h>

#include <memory>
#include <mutex>
#include <type_traits>

#include "sowing_robot/cli/usage.h"
#include "sowing_robot/ros/common/failure_log.h"
#include "sowing_robot/ros/common/inline_callback_queue.h"
#include "sowing_robot/ros/common/node_failure.h"
#include "sowing_robot/ros/common/param_reader.h"

namespace sowing_robot {

namespace detail {
// A wrapper that can end its run with a failure (run_monitor) says so with exitCode(); the others end 0.
template <typename W, typename = void>
struct HasExitCode : std::false_type {};
template <typename W>
struct HasExitCode<W, std::void_t<decltype(std::declval<const W&>().exitCode())>> : std::true_type {};
}  // namespace detail

/// `usage`: what --help prints (cli/usage.h: before ros::init, so it needs no master).
template <typename Wrapper>
int runCallbackNode(int argc, char** argv, const char* name, const char* usage) {
  cli::checkNodeArguments(argc, argv, name, usage);
  ros::init(argc, argv, name);
  InlineCallbackQueue queue;
  ros::NodeHandle nh, pnh("~");
  nh.setCallbackQueue(&queue);
  pnh.setCallbackQueue(&queue);
  std::unique_ptr<Wrapper> node;
  try {
    // A callback (a latched message on a new connection) may come before the constructor has finished.
    std::lock_guard<std::recursive_mutex> lock(queue.mutex());
    node = std::make_unique<Wrapper>(nh, pnh);
  } catch (const NodeFailure& failure) {
    // The half-built wrapper is gone (its subscriptions with it); roscpp's threads still run, so not
    // a plain return: exitProcess shuts roscpp down before the process ends.
    logFailure(ros::this_node::getName(), failure);
    exitProcess(failure.exitCode());
  }
  ros::waitForShutdown();  // returns once roscpp's threads have ended: no callback can be running
  int code = 0;
  if constexpr (detail::HasExitCode<Wrapper>::value) code = node->exitCode();
  node.reset();
  return code;
}

}  // namespace sowing_robot
