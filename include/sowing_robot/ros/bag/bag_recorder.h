// The lossless recorder of a lockstep run (sim.launch record:=), as a class: the bag_recorder node
// (src/tools/bag_recorder.cpp) drives it from its main loop, and as a nodelet (sowing_robot/recorder) it sits
// in the pipeline's manager and receives the 1 kHz topics as pointers instead of over TCP.
//
// It records the named topics without losing messages: subscribed with a large queue, drained before the
// bag is closed. ~recorded_until (std_msgs/Time, latched) is the oldest of the newest header stamps written
// on the ~period_topics (those published once per control period), and the node that ends a headless run
// (run_monitor, `~recorder`) waits for it to reach the run's last period.
//
// ~deterministic (the fleet's bags): each message is recorded at the stamp it carries (message_stamp.h)
// instead of its receive time, held for ~reorder_window of simulated time behind ~recorded_until and written
// in stamp order (stamp_order_writer.h), so two lockstep runs with the same seed give the same file bit for
// bit. What is held is written at the close; a crash loses it.
//
// A lean recording (record:=lean, docs/recording.md) keeps only what a whole field's run needs:
// ~throttle_topics are written at most once per ~throttle_period of their header stamps (the first message
// of each period: the same messages in every run, whatever the machine's speed, which a wall-clock throttle
// would not give), rosgraph_msgs/Log messages below ~min_log_level are left out, and ~compression packs the
// bag's chunks (lz4: fast enough for a 1 kHz loop). The parameters: the node's --help.
#pragma once

#include <ros/node_handle.h>

#include <cstddef>
#include <memory>

namespace sowing_robot {

class BagRecorder {
 public:
  /// Reads the private parameters of `pnh`, opens the bag and subscribes the topics on `nh`'s callback
  /// queue; announces itself ready once the period topics are linked. Throws NodeFailure (node_failure.h)
  /// on a bad parameter or a bag it cannot open.
  BagRecorder(ros::NodeHandle nh, ros::NodeHandle pnh);
  /// Closes the bag if close() was not called (the nodelet's end).
  ~BagRecorder();
  BagRecorder(const BagRecorder&) = delete;
  BagRecorder& operator=(const BagRecorder&) = delete;

  /// Ends the subscriptions of the topics that are not period topics (what the node did before it drained).
  void stopReceiving();
  /// Messages received so far (written or left out).
  std::size_t received() const;
  /// Ends every subscription (returns once no callback of the recorder is running), writes what is held,
  /// closes the bag and gives it its name; false if it could not be renamed (logged). Once only.
  bool close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sowing_robot
