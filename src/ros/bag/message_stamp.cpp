#include "sowing_robot/ros/bag/message_stamp.h"

#include <ros/serialization.h>
#include <std_msgs/Float64MultiArray.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace sowing_robot {

bool startsWithHeader(const std::string& message_definition) {
  // Line by line without copying the definition (several kB): the recorder asks for every message.
  for (std::size_t begin = 0; begin < message_definition.size();) {
    const std::size_t end = std::min(message_definition.find('\n', begin), message_definition.size());
    const std::size_t first = message_definition.find_first_not_of(" \t", begin);
    if (first < end && message_definition[first] != '#')
      return message_definition.compare(first, 13, "Header header") == 0;
    begin = end + 1;
  }
  return false;
}

namespace {

bool endsWithStampLabel(const std::string& label) {
  const std::size_t comma = label.rfind(',');
  return label.compare(comma == std::string::npos ? 0 : comma + 1, std::string::npos, kArrayStampLabel) == 0;
}

/// std_msgs/Header serialises as uint32 seq, then the stamp's uint32 sec and nsec (little-endian).
bool headerStamp(const std::vector<std::uint8_t>& bytes, ros::Time& stamp) {
  if (bytes.size() < 12) return false;
  std::uint32_t sec, nsec;
  std::memcpy(&sec, bytes.data() + 4, 4);
  std::memcpy(&nsec, bytes.data() + 8, 4);
  stamp = ros::Time(sec, nsec);
  return true;
}

/// The stamp of a message without a header first (the types messageStamp names), read from `msg`.
bool innerStamp(const topic_tools::ShapeShifter& msg, ros::Time& stamp) {
  const std::string& type = msg.getDataType();
  if (type == "visualization_msgs/MarkerArray") {
    const auto array = msg.instantiate<visualization_msgs::MarkerArray>();  // kept: the loop reads into it
    stamp = ros::Time(0, 0);
    for (const auto& m : array->markers) stamp = std::max(stamp, m.header.stamp);
    return true;
  }
  if (type == "tf2_msgs/TFMessage") {
    const auto tf = msg.instantiate<tf2_msgs::TFMessage>();
    stamp = ros::Time(0, 0);
    for (const auto& t : tf->transforms) stamp = std::max(stamp, t.header.stamp);
    return true;
  }
  if (type == "std_msgs/Float64MultiArray") {
    const auto array = msg.instantiate<std_msgs::Float64MultiArray>();
    if (array->layout.dim.empty() || array->data.empty() || !endsWithStampLabel(array->layout.dim[0].label))
      return false;
    const double t = array->data.back();
    if (!(std::isfinite(t) && t >= 0.0 && t < 4e9)) return false;
    stamp.fromSec(t);
    return true;
  }
  return false;
}

}  // namespace

bool messageStamp(const topic_tools::ShapeShifter& msg, ros::Time& stamp) {
  if (!startsWithHeader(msg.getMessageDefinition())) return innerStamp(msg, stamp);
  thread_local std::vector<std::uint8_t> bytes;  // the recorder's callbacks: no allocation per message
  bytes.resize(msg.size());
  ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  msg.write(out);
  return headerStamp(bytes, stamp);
}

bool messageStamp(const topic_tools::ShapeShifter& msg, const std::vector<std::uint8_t>& bytes, ros::Time& stamp) {
  return startsWithHeader(msg.getMessageDefinition()) ? headerStamp(bytes, stamp) : innerStamp(msg, stamp);
}

}  // namespace sowing_robot
