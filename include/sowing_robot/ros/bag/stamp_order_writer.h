// Writes a bag in an order that does not depend on when its messages arrived: what makes two lockstep runs'
// bags the same file, bit for bit (bag_recorder's ~deterministic mode, the fleet's bags).
//
// Messages are held for a reorder window of simulated time and written in the order of their key: record time
// (the stamp the message carries, message_stamp.h), then the topic's place in the recorded list, then the
// topic name and the publisher (callerid), then arrival (one connection delivers in publish order). rosbag
// numbers connections in the order of their first message, so equal messages give equal files. A message
// that arrives after the bag has been written beyond its time cannot be put in order: it is written at once
// and counted as late (its bag then depends on timing), never dropped.
//
// What only the timing of a run decides is also taken out:
// - a message equal to the one before it on its topic from the same publisher, at the same time and apart from
//   header.seq, is kept once: the lockstep loop sends a state again when an answer is late (plant_sim's
//   `lockstep_retry`) and the controllers answer it again;
// - header.seq, which roscpp counts per publish (so the resends shift it), is renumbered 0, 1, 2, ... per topic
//   and publisher, in the bag's order.
#pragma once

#include <ros/time.h>
#include <rosbag/bag.h>
#include <topic_tools/shape_shifter.h>

#include <boost/shared_ptr.hpp>

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace sowing_robot {

class StampOrderWriter {
 public:
  struct Counts {
    std::size_t written = 0;
    std::size_t repeats = 0;  ///< sent again by their publisher, kept once
    std::size_t late = 0;     ///< came after the bag was written beyond their time: written out of order
  };

  /// `bag` open for writing, outliving the writer; `topic_order` the recorded topics, in their order.
  StampOrderWriter(rosbag::Bag& bag, std::vector<std::string> topic_order);

  /// Holds a message (`bytes`, serialised) recorded at `time` (its stamp), received on `topic` through a
  /// connection with `connection_header` (callerid, latching, type, md5sum, message_definition). Returns
  /// false when it came late (written at once).
  bool add(const std::string& topic, const ros::Time& time, std::vector<std::uint8_t> bytes,
           const boost::shared_ptr<ros::M_string>& connection_header);

  /// Writes the held messages recorded before `time`, in order.
  void writeBefore(const ros::Time& time);
  /// Writes everything held (the close).
  void writeAll() { writeBefore(ros::TIME_MAX); }

  const Counts& counts() const { return counts_; }
  /// How far the bag is written: every message recorded before this time is in it.
  const ros::Time& writtenUpTo() const { return written_up_to_; }

 private:
  struct Connection {
    std::string topic, callerid;
    std::size_t rank = 0;
    boost::shared_ptr<ros::M_string> header;
    topic_tools::ShapeShifter shape;  // morphed to the connection's type once; each message is read into it
    bool has_header = false;          // std_msgs/Header first: its seq is renumbered
    std::uint32_t next_seq = 0;
    bool any = false;  // something written already: the repeat check has a predecessor
    ros::Time last_time;
    std::vector<std::uint8_t> last_bytes;  // seq zeroed
  };
  /// The order: time, then the connection's place (topic rank, topic, callerid), then arrival.
  struct Key {
    ros::Time time;
    Connection* connection;  // the map's node: stable
    std::size_t arrival;
    bool operator<(const Key& o) const;
  };

  Connection& connectionOf(const std::string& topic, const boost::shared_ptr<ros::M_string>& header);
  void write(const ros::Time& time, Connection& c, std::vector<std::uint8_t>& bytes);

  rosbag::Bag& bag_;
  std::vector<std::string> topic_order_;
  std::map<std::pair<std::string, std::string>, Connection> connections_;  // by (topic, callerid)
  std::map<Key, std::vector<std::uint8_t>> held_;                          // the serialised messages
  std::size_t arrivals_ = 0;
  ros::Time written_up_to_;  // every message before this time is in the bag
  Counts counts_;
};

/// Copies the closed bag `input` to `output` (overwritten) through a StampOrderWriter: the same file for the
/// same messages in any arrival order. Throws rosbag::BagException when a file cannot be read or written.
StampOrderWriter::Counts copyInStampOrder(const std::string& input, const std::string& output,
                                          const std::vector<std::string>& topic_order);

}  // namespace sowing_robot
