// Pairs two input streams by header stamp: the controllers compute for time t_k only when both inputs
// stamped t_k are present, which is what makes lockstep runs exact and repeatable.
#pragma once

#include <ros/time.h>

namespace sowing_robot {

template <typename A, typename B>
class StampPair {
 public:
  /// Store the newest of each; returns true when both carry the same stamp and that stamp is new.
  bool setFirst(const A& a) {
    first_ = a;
    has_first_ = true;
    return ready();
  }
  bool setSecond(const B& b) {
    second_ = b;
    has_second_ = true;
    return ready();
  }
  const A& first() const { return first_; }
  const B& second() const { return second_; }
  /// Stamp of the last pair handed out (zero before the first).
  const ros::Time& lastStamp() const { return last_; }
  bool any() const { return handed_out_; }
  /// Same stamp as the last pair handed out: the caller republishes its cached answer.
  bool isRepeat(const ros::Time& stamp) const { return handed_out_ && stamp == last_; }

 private:
  bool ready() {
    if (!has_first_ || !has_second_ || first_.header.stamp != second_.header.stamp) return false;
    if (handed_out_ && first_.header.stamp <= last_) return false;
    last_ = first_.header.stamp;
    handed_out_ = true;
    return true;
  }
  A first_;
  B second_;
  bool has_first_ = false, has_second_ = false, handed_out_ = false;
  ros::Time last_;
};

}  // namespace sowing_robot
