// bag_recorder's deterministic mode without a master: the stamp each message type carries
// (message_stamp.h), and a bag written in two different arrival orders copied to the same file, byte for
// byte (stamp_order_writer.h). Seen to fail: copying in the input's order, the two files differ.
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <std_msgs/Float64MultiArray.h>
#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>
#include <topic_tools/shape_shifter.h>
#include <unistd.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "sowing_robot/ros/bag/message_stamp.h"
#include "sowing_robot/ros/bag/stamp_order_writer.h"

namespace {

template <typename M>
topic_tools::ShapeShifter shapeOf(const M& msg) {
  std::vector<std::uint8_t> bytes(ros::serialization::serializationLength(msg));
  ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::serialize(out, msg);
  topic_tools::ShapeShifter shape;
  shape.morph(ros::message_traits::md5sum(msg), ros::message_traits::datatype(msg),
              ros::message_traits::definition(msg), "");
  ros::serialization::IStream in(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  shape.read(in);
  return shape;
}

nav_msgs::Odometry odom(double t) {
  nav_msgs::Odometry m;
  m.header.stamp.fromSec(t);
  m.pose.pose.position.x = t;
  return m;
}

std_msgs::Float64MultiArray array(const std::string& label, std::vector<double> data) {
  std_msgs::Float64MultiArray m;
  m.layout.dim.resize(1);
  m.layout.dim[0].label = label;
  m.data = std::move(data);
  return m;
}

std::string bytesOf(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

std::string tempPath(const std::string& name) { return "/tmp/test_bag_order_" + std::to_string(getpid()) + "_" + name; }

struct Written {
  std::string topic;
  double stamp;
  std::string callerid;
  std::uint32_t seq = 0;  // roscpp's count of the publisher's publishes
};

/// Writes odometry messages in the given order, each at its stamp, as two publishers would deliver them.
void writeBag(const std::string& path, const std::vector<Written>& order) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  for (const Written& w : order) {
    auto header = boost::make_shared<ros::M_string>();
    (*header)["callerid"] = w.callerid;
    (*header)["topic"] = w.topic;
    (*header)["type"] = ros::message_traits::datatype<nav_msgs::Odometry>();
    (*header)["md5sum"] = ros::message_traits::md5sum<nav_msgs::Odometry>();
    (*header)["message_definition"] = ros::message_traits::definition<nav_msgs::Odometry>();
    (*header)["latching"] = "0";
    const ros::Time t = ros::Time().fromSec(w.stamp);
    nav_msgs::Odometry m = odom(w.stamp);
    m.header.seq = w.seq;
    bag.write(w.topic, t, m, header);
  }
  bag.close();
}

}  // namespace

TEST(MessageStamp, ReadsTheStampEachTypeCarries) {
  ros::Time t;
  ASSERT_TRUE(sowing_robot::messageStamp(shapeOf(odom(12.5)), t));
  EXPECT_EQ(t, ros::Time(12, 500000000));
  // the same from bytes already serialised (the recorder's deterministic mode)
  const nav_msgs::Odometry o = odom(7.25);
  std::vector<std::uint8_t> bytes(ros::serialization::serializationLength(o));
  ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::serialize(out, o);
  ASSERT_TRUE(sowing_robot::messageStamp(shapeOf(o), bytes, t));
  EXPECT_EQ(t, ros::Time(7, 250000000));
  EXPECT_TRUE(sowing_robot::startsWithHeader("# a comment\n\n  \t\n  Header header\nfloat64 x\n"));
  EXPECT_FALSE(sowing_robot::startsWithHeader("float64 x\nHeader header\n"));
  EXPECT_FALSE(sowing_robot::startsWithHeader("# only a comment\n"));
  EXPECT_FALSE(sowing_robot::startsWithHeader(""));

  visualization_msgs::MarkerArray markers;
  markers.markers.resize(3);
  markers.markers[0].header.stamp = ros::Time(3, 0);
  markers.markers[1].header.stamp = ros::Time(7, 5);
  ASSERT_TRUE(sowing_robot::messageStamp(shapeOf(markers), t));
  EXPECT_EQ(t, ros::Time(7, 5));  // the newest

  tf2_msgs::TFMessage tf;
  tf.transforms.resize(2);
  tf.transforms[1].header.stamp = ros::Time(4, 2);
  ASSERT_TRUE(sowing_robot::messageStamp(shapeOf(tf), t));
  EXPECT_EQ(t, ros::Time(4, 2));

  ASSERT_TRUE(sowing_robot::messageStamp(shapeOf(array("a,b,stamp", {1.0, 2.0, 2.25})), t));
  EXPECT_EQ(t, ros::Time(2, 250000000));
  ASSERT_TRUE(sowing_robot::messageStamp(shapeOf(array("stamp", {6.0})), t));
  EXPECT_EQ(t, ros::Time(6, 0));

  // no stamp to be had: an array without the label (or a word only ending in it), a NaN stamp, a String
  EXPECT_FALSE(sowing_robot::messageStamp(shapeOf(array("a,b", {1.0, 2.0})), t));
  EXPECT_FALSE(sowing_robot::messageStamp(shapeOf(array("a,timestamp", {1.0, 2.0})), t));
  EXPECT_FALSE(sowing_robot::messageStamp(shapeOf(array("a,stamp", {1.0, std::nan("")})), t));
  EXPECT_FALSE(sowing_robot::messageStamp(shapeOf(array("a,stamp", {})), t));
  std_msgs::String text;
  text.data = "no header";
  EXPECT_FALSE(sowing_robot::messageStamp(shapeOf(text), t));
}

TEST(StampSortedCopy, TwoArrivalOrdersGiveTheSameFile) {
  // Three topics from two publishers; ties at equal stamps across topics.
  std::vector<Written> a = {{"/odom", 1.0, "/plant"},   {"/ground_truth", 1.0, "/plant"}, {"/odom", 2.0, "/plant"},
                            {"/filtered", 1.0, "/ekf"}, {"/ground_truth", 2.0, "/plant"}, {"/filtered", 2.0, "/ekf"},
                            {"/odom", 3.0, "/plant"}};
  std::vector<Written> b = {{"/filtered", 1.0, "/ekf"}, {"/ground_truth", 1.0, "/plant"},
                            {"/filtered", 2.0, "/ekf"}, {"/ground_truth", 2.0, "/plant"},
                            {"/odom", 1.0, "/plant"},   {"/odom", 2.0, "/plant"},
                            {"/odom", 3.0, "/plant"}};
  const std::string in_a = tempPath("a.bag"), in_b = tempPath("b.bag"), out_a = tempPath("a_sorted.bag"),
                    out_b = tempPath("b_sorted.bag");
  writeBag(in_a, a);
  writeBag(in_b, b);
  ASSERT_NE(bytesOf(in_a), bytesOf(in_b));  // the arrival order shows in the files
  const std::vector<std::string> order = {"/ground_truth", "/odom", "/filtered"};
  EXPECT_EQ(sowing_robot::copyInStampOrder(in_a, out_a, order).written, a.size());
  EXPECT_EQ(sowing_robot::copyInStampOrder(in_b, out_b, order).written, b.size());
  EXPECT_EQ(bytesOf(out_a), bytesOf(out_b));

  // The order: by stamp, then by the topic's place in the list. rosbag numbers the connections in the order
  // of their first message (its View merges equal times in no particular order, so the ids are what shows it).
  rosbag::Bag sorted(out_a, rosbag::bagmode::Read);
  rosbag::View view(sorted);
  std::vector<std::string> by_id(3);
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    ASSERT_LT(c->id, 3u);
    by_id[c->id] = c->topic;
  }
  EXPECT_EQ(by_id, (std::vector<std::string>{"/ground_truth", "/odom", "/filtered"}));
  std::vector<double> stamps;
  for (const rosbag::MessageInstance& m : view) stamps.push_back(m.getTime().toSec());
  EXPECT_EQ(stamps, (std::vector<double>{1, 1, 1, 2, 2, 2, 3}));
  sorted.close();
  for (const std::string& p : {in_a, in_b, out_a, out_b}) std::remove(p.c_str());
}

TEST(StampSortedCopy, AResentStateIsKeptOnceAndSeqRenumbered) {
  // Run A: the state at t = 2 sent again (lockstep retry): roscpp counted it, so the later seqs are shifted.
  std::vector<Written> a = {{"/odom", 1.0, "/plant", 10},
                            {"/odom", 2.0, "/plant", 11},
                            {"/odom", 2.0, "/plant", 12},
                            {"/odom", 3.0, "/plant", 13}};
  std::vector<Written> b = {{"/odom", 1.0, "/plant", 10}, {"/odom", 2.0, "/plant", 11}, {"/odom", 3.0, "/plant", 12}};
  const std::string in_a = tempPath("ra.bag"), in_b = tempPath("rb.bag"), out_a = tempPath("ra_sorted.bag"),
                    out_b = tempPath("rb_sorted.bag");
  writeBag(in_a, a);
  writeBag(in_b, b);
  const sowing_robot::StampOrderWriter::Counts ca = sowing_robot::copyInStampOrder(in_a, out_a, {"/odom"});
  EXPECT_EQ(ca.written, 3u);
  EXPECT_EQ(ca.repeats, 1u);
  EXPECT_EQ(sowing_robot::copyInStampOrder(in_b, out_b, {"/odom"}).repeats, 0u);
  EXPECT_EQ(bytesOf(out_a), bytesOf(out_b));
  rosbag::Bag sorted(out_a, rosbag::bagmode::Read);
  std::vector<std::uint32_t> seqs;
  for (const rosbag::MessageInstance& m : rosbag::View(sorted))
    seqs.push_back(m.instantiate<nav_msgs::Odometry>()->header.seq);
  EXPECT_EQ(seqs, (std::vector<std::uint32_t>{0, 1, 2}));
  sorted.close();

  // The same stamp with other content is not a repeat: both are kept.
  const std::string in_c = tempPath("rc.bag"), out_c = tempPath("rc_sorted.bag");
  {
    rosbag::Bag bag(in_c, rosbag::bagmode::Write);
    nav_msgs::Odometry m = odom(1.0);
    bag.write("/odom", m.header.stamp, m);
    m.pose.pose.position.y = 0.5;
    bag.write("/odom", m.header.stamp, m);
    bag.close();
  }
  const sowing_robot::StampOrderWriter::Counts cc = sowing_robot::copyInStampOrder(in_c, out_c, {"/odom"});
  EXPECT_EQ(cc.written, 2u);
  EXPECT_EQ(cc.repeats, 0u);
  for (const std::string& p : {in_a, in_b, out_a, out_b, in_c, out_c}) std::remove(p.c_str());
}

TEST(StampOrderWriter, HoldsForTheWindowAndWritesALateMessageAtOnce) {
  const std::string path = tempPath("late.bag");
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  sowing_robot::StampOrderWriter writer(bag, {"/odom", "/seeds"});
  auto header = boost::make_shared<ros::M_string>();
  (*header)["callerid"] = "/plant";
  (*header)["type"] = ros::message_traits::datatype<nav_msgs::Odometry>();
  (*header)["md5sum"] = ros::message_traits::md5sum<nav_msgs::Odometry>();
  (*header)["message_definition"] = ros::message_traits::definition<nav_msgs::Odometry>();
  auto bytesOfOdom = [](double t) {
    const nav_msgs::Odometry m = odom(t);
    std::vector<std::uint8_t> b(ros::serialization::serializationLength(m));
    ros::serialization::OStream out(b.data(), static_cast<std::uint32_t>(b.size()));
    ros::serialization::serialize(out, m);
    return b;
  };
  for (double t : {3.0, 1.0, 2.0}) EXPECT_TRUE(writer.add("/odom", ros::Time().fromSec(t), bytesOfOdom(t), header));
  EXPECT_EQ(writer.counts().written, 0u);  // held
  writer.writeBefore(ros::Time(2, 500000000));
  EXPECT_EQ(writer.counts().written, 2u);  // 1 and 2, in order; 3 still held
  EXPECT_EQ(writer.writtenUpTo(), ros::Time(2, 500000000));
  EXPECT_FALSE(writer.add("/seeds", ros::Time(2, 0), bytesOfOdom(2.0), header));  // late: written at once
  EXPECT_EQ(writer.counts().late, 1u);
  EXPECT_EQ(writer.counts().written, 3u);
  writer.writeAll();
  EXPECT_EQ(writer.counts().written, 4u);
  bag.close();
  rosbag::Bag in(path, rosbag::bagmode::Read);
  EXPECT_EQ(rosbag::View(in).size(), 4u);  // nothing lost
  in.close();
  std::remove(path.c_str());
}

TEST(StampSortedCopy, AMissingInputIsABagException) {
  EXPECT_THROW(sowing_robot::copyInStampOrder(tempPath("none.bag"), tempPath("none_out.bag"), {}),
               rosbag::BagException);
}
