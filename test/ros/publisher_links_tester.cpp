// rostest (publisher_links.test): linkedSubscribers / firstUnlinkedTopic / waitUntilLinked
// (ros/common/publisher_links.h), what the lockstep start-up handshake and the testers wait for. A topic is linked
// only while a publisher lists this node's link: not when nobody publishes it, not when its publisher (the .test's
// rostopic talker) has a link to another node (the .test's listener) but not to this one, and no longer once this
// node has unsubscribed; in one process (a nodelet manager) the intra-process link counts. Fails without what it
// protects: an answer that ignored the link's destination says "linked" while only the listener is linked; a call
// without a timeout hangs on a publisher that never answers.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <std_msgs/Int32.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <string>
#include <vector>

#include "sowing_robot/ros/common/publisher_links.h"

using namespace sowing_robot;

namespace {
const double kTimeout = 30.0;

/// Waits until the master lists a publisher of `topic` (the talker may start after this tester).
bool published(const std::string& topic) {
  const ros::WallTime start = ros::WallTime::now();
  while ((ros::WallTime::now() - start).toSec() < kTimeout) {
    ros::master::V_TopicInfo topics;
    ros::master::getTopics(topics);
    for (const auto& t : topics)
      if (t.name == topic) return true;
    ros::WallDuration(0.01).sleep();
  }
  return false;
}

/// Waits until a publisher of `topic` lists a link to `node`.
bool listed(const std::string& topic, const std::string& node) {
  const ros::WallTime start = ros::WallTime::now();
  while ((ros::WallTime::now() - start).toSec() < kTimeout) {
    const std::vector<std::string> linked = linkedSubscribers(topic);
    if (std::find(linked.begin(), linked.end(), node) != linked.end()) return true;
    ros::WallDuration(0.01).sleep();
  }
  return false;
}

/// Waits until `topic` is unlinked again (the publisher drops the link when it notices the socket closed).
bool unlinkedWithin(const std::string& topic) {
  const ros::WallTime start = ros::WallTime::now();
  while ((ros::WallTime::now() - start).toSec() < kTimeout) {
    if (firstUnlinkedTopic({topic}) == topic) return true;
    ros::WallDuration(0.01).sleep();
  }
  return false;
}
}  // namespace

TEST(PublisherLinks, ATopicNobodyPublishesIsUnlinked) {
  EXPECT_EQ(firstUnlinkedTopic({"/nobody_publishes_this"}), "/nobody_publishes_this");
  std::string unlinked;
  EXPECT_FALSE(waitUntilLinked({"/nobody_publishes_this"}, 0.1, &unlinked));
  EXPECT_EQ(unlinked, "/nobody_publishes_this");
}

TEST(PublisherLinks, LinkedOnlyWhileThePublisherListsThisNode) {
  ros::NodeHandle nh;
  ASSERT_TRUE(published("/links_probe")) << "the talker of publisher_links.test never advertised /links_probe";
  ASSERT_TRUE(listed("/links_probe", "/listener")) << "the talker never linked the listener of publisher_links.test";
  EXPECT_EQ(firstUnlinkedTopic({"/links_probe"}), "/links_probe") << "linked before subscribing (another's link?)";
  int received = 0;
  ros::Subscriber sub =
      nh.subscribe<std_msgs::Int32>("links_probe", 10, [&](const std_msgs::Int32::ConstPtr&) { ++received; });
  std::string unlinked;
  ASSERT_TRUE(waitUntilLinked({sub.getTopic()}, kTimeout, &unlinked)) << unlinked;
  EXPECT_EQ(firstUnlinkedTopic({"/links_probe", "/nobody_publishes_this"}), "/nobody_publishes_this")
      << "the first unlinked of several";
  const ros::WallTime start = ros::WallTime::now();
  while (received == 0 && (ros::WallTime::now() - start).toSec() < kTimeout) {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  EXPECT_GT(received, 0) << "linked, yet nothing came";
  sub.shutdown();
  EXPECT_TRUE(unlinkedWithin("/links_probe")) << "still linked after unsubscribing";
}

TEST(PublisherLinks, AnIntraProcessLinkCounts) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<std_msgs::Int32>("links_local", 1);
  EXPECT_EQ(firstUnlinkedTopic({pub.getTopic()}), pub.getTopic()) << "linked before subscribing";
  ros::Subscriber sub = nh.subscribe<std_msgs::Int32>(
      "links_local", 1,
      boost::function<void(const std_msgs::Int32::ConstPtr&)>([](const std_msgs::Int32::ConstPtr&) {}));
  std::string unlinked;
  EXPECT_TRUE(waitUntilLinked({sub.getTopic()}, kTimeout, &unlinked)) << unlinked;
}

// A publisher whose XML-RPC port accepts connections but never answers (a stopped process: the kernel still
// completes the handshake): the question must come back unlinked, not hang the caller (plant_sim's lockstep thread
// asks it before step 0). Without the bounded call this test hangs until the .test's time limit.
TEST(PublisherLinks, APublisherThatNeverAnswersIsUnlinked) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof addr;
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ASSERT_EQ(listen(fd, 4), 0);
  ASSERT_EQ(getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len), 0);
  const std::string api = "http://127.0.0.1:" + std::to_string(ntohs(addr.sin_port)) + "/";
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = "/mute_publisher";
  request[1] = "/links_mute";
  request[2] = "std_msgs/Int32";
  request[3] = api;
  ASSERT_TRUE(ros::master::execute("registerPublisher", request, response, payload, false));
  EXPECT_EQ(firstUnlinkedTopic({"/links_mute"}), "/links_mute");
  XmlRpc::XmlRpcValue unregister;
  unregister[0] = "/mute_publisher";
  unregister[1] = "/links_mute";
  unregister[2] = api;
  ros::master::execute("unregisterPublisher", unregister, response, payload, false);
  close(fd);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "publisher_links_tester");
  ros::NodeHandle nh;  // starts the node: the master and the XML-RPC server answer from here on
  return RUN_ALL_TESTS();
}
