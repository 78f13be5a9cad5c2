// The time a message carries, read from its serialised bytes whatever its type: what bag_recorder's
// deterministic mode records each message at (the receive time differs from run to run, the stamp does not).
#pragma once

#include <ros/time.h>
#include <topic_tools/shape_shifter.h>

#include <cstdint>
#include <string>
#include <vector>

namespace sowing_robot {

/// Appended as the last element of a std_msgs/Float64MultiArray by the package's own array topics
/// (`wheel_slip`, `seed_report`), with this label last in layout.dim[0].label, so that they carry a stamp too.
constexpr const char* kArrayStampLabel = "stamp";

/// The stamp of `msg`, or false when it carries none. In this order:
/// - a message whose first field is a std_msgs/Header: that header's stamp;
/// - visualization_msgs/MarkerArray, tf2_msgs/TFMessage: the newest stamp among its markers / transforms
///   (an empty array: time 0);
/// - std_msgs/Float64MultiArray whose comma-separated dim[0] label ends with `stamp`: that last element [s].
bool messageStamp(const topic_tools::ShapeShifter& msg, ros::Time& stamp);
/// The same, with `bytes` the message already serialised (the recorder's deterministic mode holds them anyway).
bool messageStamp(const topic_tools::ShapeShifter& msg, const std::vector<std::uint8_t>& bytes, ros::Time& stamp);

/// True when the message definition's first field is `Header header` (comments and blank lines skipped).
bool startsWithHeader(const std::string& message_definition);

}  // namespace sowing_robot
