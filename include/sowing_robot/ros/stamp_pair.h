// Pairs two input streams by header stamp: the controllers compute for time t_k only when both inputs
// stamped t_k are present, which is what makes lockstep runs exact and repeatable.
#pragma once

#include <ros/time.h>

#include <array>
#include <cstddef>

namespace sowing_robot {

template <typename A, typename B>
class StampPair {
 public:
  /// Messages kept per stream. Two, because the reference generator publishes the reference for
  /// t_{k+1} as soon as it has the state for t_k: the kinematic controller may then hold the references
  /// for t_k and t_{k+1} when the state for t_k arrives.
  static constexpr std::size_t kDepth = 2;

  /// Store a message (the oldest of its stream is dropped); returns true when a stamp present in both
  /// streams is newer than the last pair handed out. first() and second() are then that pair.
  bool setFirst(const A& a) {
    firsts_.push(a);
    return match();
  }
  bool setSecond(const B& b) {
    seconds_.push(b);
    return match();
  }
  const A& first() const { return firsts_.at(first_index_); }
  const B& second() const { return seconds_.at(second_index_); }
  /// Stamp of the last pair handed out (zero before the first).
  const ros::Time& lastStamp() const { return last_; }
  bool any() const { return handed_out_; }
  /// Same stamp as the last pair handed out: the caller republishes its cached answer.
  bool isRepeat(const ros::Time& stamp) const { return handed_out_ && stamp == last_; }

 private:
  template <typename T>
  struct Ring {
    std::array<T, kDepth> items{};
    std::size_t count = 0, next = 0;
    void push(const T& m) {
      items[next] = m;
      next = (next + 1) % kDepth;
      if (count < kDepth) ++count;
    }
    const T& at(std::size_t i) const { return items[i]; }
  };

  bool match() {
    bool found = false;
    ros::Time best;
    for (std::size_t i = 0; i < firsts_.count; ++i) {
      const ros::Time& stamp = firsts_.items[i].header.stamp;
      if ((handed_out_ && stamp <= last_) || (found && stamp <= best)) continue;
      for (std::size_t j = 0; j < seconds_.count; ++j) {
        if (seconds_.items[j].header.stamp != stamp) continue;
        found = true;
        best = stamp;
        first_index_ = i;
        second_index_ = j;
      }
    }
    if (!found) return false;
    last_ = best;
    handed_out_ = true;
    return true;
  }

  Ring<A> firsts_;
  Ring<B> seconds_;
  std::size_t first_index_ = 0, second_index_ = 0;
  bool handed_out_ = false;
  ros::Time last_;
};

}  // namespace sowing_robot
