#include "sowing_robot/ros/bag/stamp_order_writer.h"

#include <ros/serialization.h>
#include <rosbag/view.h>
#include <topic_tools/shape_shifter.h>

#include <algorithm>
#include <cstring>
#include <tuple>

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
    const std::string definition = field(h, "message_definition");
    c.shape.morph(field(h, "md5sum"), field(h, "type"), definition, field(h, "latching") == "1" ? "1" : "0");
    c.has_header = startsWithHeader(definition);
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
  held_.emplace(Key{time, &c, arrivals_++}, std::move(bytes));
  return true;
}

bool StampOrderWriter::Key::operator<(const Key& o) const {
  if (time != o.time) return time < o.time;
  if (connection != o.connection)
    return std::tie(connection->rank, connection->topic, connection->callerid) <
           std::tie(o.connection->rank, o.connection->topic, o.connection->callerid);
  return arrival < o.arrival;
}

void StampOrderWriter::writeBefore(const ros::Time& time) {
  auto it = held_.begin();
  for (; it != held_.end() && it->first.time < time; ++it) write(it->first.time, *it->first.connection, it->second);
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
  ros::serialization::IStream from(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  c.shape.read(from);
  bag_.write(c.topic, time, c.shape, c.header);
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
