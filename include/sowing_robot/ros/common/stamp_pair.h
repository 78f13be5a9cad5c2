// Pairs two input streams by header stamp: the controllers compute for time t_k only when both inputs
// stamped t_k are present, which is what makes lockstep runs exact and repeatable.
#pragma once

#include <ros/time.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace sowing_robot {

/// Each stream keeps the messages newer than the last pair handed out, up to its cap (then the oldest
/// goes, counted by dropped()): the second stream must hold every reference the generator sends ahead
/// of the state (lookahead / control period of them, 50 at the defaults). The controllers, which the
/// plant waits for, need only the newest few states in the first; a listener the plant does not wait for
/// (run_monitor, seed_drill) can see the states run far ahead of the references (another connection,
/// another process) and must hold them all until their references come.
template <typename A, typename B, std::size_t kMaxFirsts = 8, std::size_t kMaxSeconds = 8192>
class StampPair {
 public:
  /// Store a message; returns true when a stamp present in both streams is newer than the last pair
  /// handed out. first() and second() are then that pair, valid until the next set call.
  bool setFirst(const A& a) {
    prune();
    firsts_.push(a, kMaxFirsts);
    return matchNewest(firsts_, first_index_, seconds_, second_index_);
  }
  bool setSecond(const B& b) {
    prune();
    seconds_.push(b, kMaxSeconds);
    return matchNewest(seconds_, second_index_, firsts_, first_index_);
  }
  const A& first() const { return firsts_.at(first_index_); }
  const B& second() const { return seconds_.at(second_index_); }
  /// Stamp of the last pair handed out (zero before the first).
  const ros::Time& lastStamp() const { return last_; }
  bool any() const { return handed_out_; }
  /// Same stamp as the last pair handed out: the caller republishes its cached answer.
  bool isRepeat(const ros::Time& stamp) const { return handed_out_ && stamp == last_; }
  /// Messages held (tests, diagnostics).
  std::size_t heldFirsts() const { return firsts_.count; }
  std::size_t heldSeconds() const { return seconds_.count; }
  /// Messages pushed out by a full stream before they were paired (or passed): each is a stamp that
  /// will never pair.
  std::size_t dropped() const { return firsts_.dropped + seconds_.dropped; }
  /// A second stamped after `stamp` is held: a first stamped `stamp` with no second means the two
  /// streams are on different time grids (a control_rate mismatch), not a second still on its way.
  bool secondsPassed(const ros::Time& stamp) const {
    for (std::size_t i = 0; i < seconds_.count; ++i)
      if (seconds_.at(i).header.stamp > stamp) return true;
    return false;
  }

 private:
  /// A ring in arrival order that doubles (rarely: only while the lookahead fills it) up to `cap`.
  template <typename T>
  struct Ring {
    std::vector<T> items = std::vector<T>(2);
    std::size_t head = 0, count = 0, dropped = 0;
    const T& at(std::size_t i) const { return items[(head + i) % items.size()]; }
    void push(const T& m, std::size_t cap) {
      if (count == items.size()) {
        if (items.size() < cap) {
          std::vector<T> grown(std::min(cap, 2 * items.size()));
          for (std::size_t i = 0; i < count; ++i) grown[i] = at(i);
          items.swap(grown);
          head = 0;
        } else {
          popFront();
          ++dropped;
        }
      }
      items[(head + count) % items.size()] = m;
      ++count;
    }
    void popFront() {
      head = (head + 1) % items.size();
      --count;
    }
    /// Drops the oldest messages while they are not newer than `last` (they can never pair again).
    void dropUpTo(const ros::Time& last) {
      while (count > 0 && at(0).header.stamp <= last) popFront();
    }
  };

  /// Messages the last pair made useless (the pair included) go before a new one is stored, not at
  /// once: first() and second() refer into the rings until then.
  void prune() {
    if (!handed_out_) return;
    firsts_.dropUpTo(last_);
    seconds_.dropUpTo(last_);
  }

  /// Only the message just stored (the newest of `added`) can complete a pair: after every call no
  /// two held messages newer than the last pair share a stamp (a match hands out the newest, and what
  /// is older goes with the next prune()), so one pass over the other stream finds it.
  template <typename X, typename Y>
  bool matchNewest(const Ring<X>& added, std::size_t& added_index, const Ring<Y>& other, std::size_t& other_index) {
    const std::size_t i = added.count - 1;
    const ros::Time& stamp = added.at(i).header.stamp;
    if (handed_out_ && stamp <= last_) return false;
    for (std::size_t j = 0; j < other.count; ++j) {
      if (other.at(j).header.stamp != stamp) continue;
      added_index = i;
      other_index = j;
      last_ = stamp;
      handed_out_ = true;
      return true;
    }
    return false;
  }

  Ring<A> firsts_;
  Ring<B> seconds_;
  std::size_t first_index_ = 0, second_index_ = 0;
  bool handed_out_ = false;
  ros::Time last_;
};

/// For a node the plant does not wait for (run_monitor, seed_drill) or one whose two inputs come from
/// different processes at the same pace (state_estimator): either stream can run a whole lookahead ahead.
template <typename A, typename B>
using ListenerPair = StampPair<A, B, 8192, 8192>;

}  // namespace sowing_robot
