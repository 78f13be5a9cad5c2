#include "sowing_robot/ros/bag/stamp_order_writer.h"

#include <ros/serialization.h>
#include <rosbag/view.h>
#include <topic_tools/shape_shifter.h>

#include <algorithm>
#include <cstring>

#include "sowing_robot/ros/bag/message_stamp.h"

namespace sowing_robot {

namespace {

std::string field(const ros::M_string& header, const std::string& key) {
  const auto it = header.find(key);
  return it == header.end() ? std::string() : it->second;
}

}  // namespace

StampOrderWriter::StampOrderWriter(rosbag::Bag& bag, std::vector<std::string> topic_order)
    : bag_(bag), topic_order_(std::move(topic_order)), written_up_to_(ros::TIME_MIN) {}

StampOrderWriter::Connection& StampOrderWriter::connectionOf(const std::string& topic,
                                                             const boost::shared_ptr<ros::M_string>& header) {
  static const ros::M_string kNone;
  const ros::M_string& h = header ? *header : kNone;
  const std::string callerid = field(h, "callerid");
  auto [it, first] = connections_.try_emplace({topic, callerid});
  Connection& c = it->second;
  if (first) {
    c.topic = topic;
    c.callerid = callerid;
    c.rank =
        static_cast<std::size_t>(std::find(topic_order_.begin(), topic_order_.end(), topic) - topic_order_.begin());
    c.header = header;
    c.md5 = field(h, "md5sum");
    c.type = field(h, "type");
    c.definition = field(h, "message_definition");
    c.latching = field(h, "latching") == "1" ? "1" : "0";
    c.has_header = startsWithHeader(c.definition);
  }
  return c;
}

bool StampOrderWriter::add(const std::string& topic, const ros::Time& time, std::vector<std::uint8_t> bytes,
                           const boost::shared_ptr<ros::M_string>& connection_header) {
  Connection& c = connectionOf(topic, connection_header);
  if (time < written_up_to_) {
    ++counts_.late;
    write(time, c, bytes);
    return false;
  }
  held_.emplace(Key{time, c.rank, c.topic, c.callerid, arrivals_++}, Held{&c, std::move(bytes)});
  return true;
}

void StampOrderWriter::writeBefore(const ros::Time& time) {
  auto it = held_.begin();
  for (; it != held_.end() && std::get<0>(it->first) < time; ++it)
    write(std::get<0>(it->first), *it->second.connection, it->second.bytes);
  held_.erase(held_.begin(), it);
  written_up_to_ = std::max(written_up_to_, time);
}

void StampOrderWriter::write(const ros::Time& time, Connection& c, std::vector<std::uint8_t>& bytes) {
  const bool seq = c.has_header && bytes.size() >= 4;  // std_msgs/Header starts with uint32 seq
  if (seq) std::memset(bytes.data(), 0, 4);
  if (c.any && c.last_time == time && c.last_bytes == bytes) {
    ++counts_.repeats;
    return;
  }
  c.any = true;
  c.last_time = time;
  c.last_bytes = bytes;
  if (seq) {
    std::memcpy(bytes.data(), &c.next_seq, 4);  // little-endian, as ROS serialises
    ++c.next_seq;
  }
  topic_tools::ShapeShifter shape;
  shape.morph(c.md5, c.type, c.definition, c.latching);
  ros::serialization::IStream from(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  shape.read(from);
  bag_.write(c.topic, time, shape, c.header);
  ++counts_.written;
}

StampOrderWriter::Counts copyInStampOrder(const std::string& input, const std::string& output,
                                          const std::vector<std::string>& topic_order) {
  rosbag::Bag in(input, rosbag::bagmode::Read);
  rosbag::Bag out(output, rosbag::bagmode::Write);
  StampOrderWriter writer(out, topic_order);
  for (const rosbag::MessageInstance& m : rosbag::View(in)) {
    std::vector<std::uint8_t> bytes(m.size());
    ros::serialization::OStream to(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
    m.write(to);
    writer.add(m.getTopic(), m.getTime(), std::move(bytes), m.getConnectionHeader());
  }
  writer.writeAll();
  out.close();
  return writer.counts();
}

}  // namespace sowing_robot
