// bag_recorder: records the named topics into a bag without losing messages in lockstep runs.
//
// The recording itself (what is kept, ~recorded_until, the stamp order, the lean throttle) is
// sowing_robot::BagRecorder (ros/bag/bag_recorder.h), which the pipeline's manager also loads as the nodelet
// sowing_robot/recorder. This node serves it from its main loop and, on SIGINT (roslaunch's shutdown, Ctrl-C),
// first drains every message already received, then closes the bag: complete, indexed, nothing recorded is
// lost. What it has not received yet it cannot drain: a recorder seconds of simulated time behind the loop (a
// loaded machine) would lose them with their publishers when the launch ends; ~recorded_until says how far it
// has got, and run_monitor waits for it. Usage: kUsage below (--help).
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <csignal>
#include <cstddef>

#include "sowing_robot/cli/usage.h"
#include "sowing_robot/ros/bag/bag_recorder.h"
#include "sowing_robot/ros/common/failure_log.h"
#include "sowing_robot/ros/common/node_failure.h"
#include "sowing_robot/ros/common/param_reader.h"

namespace {
const char* const kUsage = SOWING_NODE_USAGE(
    "bag_recorder",
    "Records the named topics into a bag without losing messages in lockstep runs (sim.launch record:=):\n"
    "  rosrun sowing_robot bag_recorder _output:=run.bag _topics:=\"/odom /reference ...\" [_queue:=200000]\n"
    "    [_period_topics:=\"/odom ...\"] [_deterministic:=false [_reorder_window:=5]] [_receive_delay:=0 (s per\n"
    "    message, tests: a recorder starved of CPU)] [_throttle_topics:=\"/odom ...\" _throttle_period:=0.1 (s of\n"
    "    their stamps)] [_min_log_level:=0 (rosgraph_msgs/Log below it left out: 4 warnings and above)]\n"
    "    [_compression:=none|lz4|bz2]\n"
    "On SIGINT it drains what it has received, then closes the bag; ~recorded_until says how far it got.\n"
    "_deterministic:=true records each message at its own stamp and writes the bag in stamp order (held for\n"
    "_reorder_window seconds of simulated time): two lockstep runs with the same seed give the same file.\n");

volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }

/// Keeps writing what arrives until nothing has for a second.
void drain(ros::CallbackQueue& q, const sowing_robot::BagRecorder& recorder) {
  for (ros::WallTime quiet = ros::WallTime::now(); (ros::WallTime::now() - quiet).toSec() < 1.0;) {
    const std::size_t before = recorder.received();
    q.callAvailable(ros::WallDuration(0.05));
    if (recorder.received() != before) quiet = ros::WallTime::now();
  }
}

int record(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  sowing_robot::BagRecorder recorder(nh, pnh);
  ros::CallbackQueue* q = ros::getGlobalCallbackQueue();
  while (!g_stop && ros::ok()) q->callAvailable(ros::WallDuration(0.1));
  // Drain: keep writing until nothing has arrived for a second, then close.
  recorder.stopReceiving();
  drain(*q, recorder);
  return recorder.close() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  sowing_robot::cli::checkNodeArguments(argc, argv, "bag_recorder", kUsage);
  ros::init(argc, argv, "bag_recorder", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  ros::NodeHandle nh, pnh("~");
  int code = 0;
  try {
    code = record(nh, pnh);
  } catch (const sowing_robot::NodeFailure& failure) {
    sowing_robot::logFailure(ros::this_node::getName(), failure);
    sowing_robot::exitProcess(failure.exitCode());
  }
  ros::shutdown();
  return code;
}
