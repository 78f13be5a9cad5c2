// bag_recorder: records the named topics into a bag without losing messages in lockstep runs.
//
// rosbag record subscribes with a fixed queue of 100 messages; a lockstep run does not wait for it, so
// on a loaded machine it drops whole blocks (measured: up to 241 of 25,001 tracking errors). This
// recorder subscribes with a large queue, and on SIGINT (roslaunch's shutdown, Ctrl-C) it first drains
// every message already received, then closes the bag: complete, indexed, nothing recorded is lost.
//   rosrun sowing_robot bag_recorder _output:=run.bag _topics:="/odom /reference ..." [_queue:=200000]
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <topic_tools/shape_shifter.h>

#include <csignal>
#include <sstream>
#include <string>
#include <vector>

namespace {
volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "bag_recorder", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  ros::NodeHandle nh, pnh("~");
  std::string output, topic_list;
  int queue = 200000;
  pnh.getParam("output", output);
  pnh.getParam("topics", topic_list);
  pnh.getParam("queue", queue);
  std::vector<std::string> topics;
  std::istringstream ss(topic_list);
  for (std::string t; ss >> t;) topics.push_back(t);
  if (output.empty() || topics.empty() || queue < 1) {
    ROS_FATAL("bag_recorder: refusing to start: ~output (a path) and ~topics (space-separated) are required, "
              "~queue >= 1 (got output '%s', %zu topics, queue %d)", output.c_str(), topics.size(), queue);
    return 1;
  }
  rosbag::Bag bag;
  const std::string active = output + ".active";
  try {
    bag.open(active, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    ROS_FATAL("bag_recorder: cannot open %s: %s", active.c_str(), e.what());
    return 1;
  }
  std::size_t written = 0;
  std::vector<ros::Subscriber> subs;
  for (const std::string& topic : topics) {
    boost::function<void(const ros::MessageEvent<topic_tools::ShapeShifter const>&)> cb =
        [&bag, &written, topic](const ros::MessageEvent<topic_tools::ShapeShifter const>& event) {
          ros::Time t = ros::Time::now();
          if (t < ros::TIME_MIN) t = ros::TIME_MIN;  // before the first /clock
          bag.write(topic, t, event.getMessage(), event.getConnectionHeaderPtr());
          ++written;
        };
    subs.push_back(nh.subscribe<topic_tools::ShapeShifter>(topic, static_cast<std::uint32_t>(queue), cb,
                                                           ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  ROS_INFO("bag_recorder: recording %zu topics to %s", topics.size(), output.c_str());
  ros::CallbackQueue* q = ros::getGlobalCallbackQueue();
  while (!g_stop && ros::ok()) q->callAvailable(ros::WallDuration(0.1));
  // Drain: keep writing until nothing has arrived for a second, then close.
  subs.clear();
  for (ros::WallTime quiet = ros::WallTime::now(); (ros::WallTime::now() - quiet).toSec() < 1.0;) {
    const std::size_t before = written;
    q->callAvailable(ros::WallDuration(0.05));
    if (written != before) quiet = ros::WallTime::now();
  }
  bag.close();
  if (std::rename(active.c_str(), output.c_str()) != 0) {
    ROS_ERROR("bag_recorder: could not rename %s to %s", active.c_str(), output.c_str());
    return 1;
  }
  std::printf("bag_recorder: %zu messages written to %s\n", written, output.c_str());
  std::fflush(stdout);
  ros::shutdown();
  return 0;
}
