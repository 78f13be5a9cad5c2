// InlineCallbackQueue for a queue whose mutex a thread of its own also holds while it publishes: the
// lockstep plant's wheel_torque queue (plant_sim_lockstep.h).
#pragma once

#include <ros/callback_queue_interface.h>

#include <cstdint>
#include <deque>
#include <mutex>

namespace sowing_robot {

/// Runs each callback at once in the queuing thread, under one recursive mutex, like InlineCallbackQueue;
/// but a thread that finds the mutex taken does not wait for it: it leaves the callback to the holder,
/// which runs it when it lets go (Hold), in the order queued.
///
/// Why: roscpp publishes in-process (nodelets) holding its TopicManager lock while it queues the
/// subscribers' callbacks. The plant's run thread holds this mutex while it publishes step 0 (or a
/// re-sent state), and so wants the TopicManager lock second; a torque controller that answers that
/// state on its own thread holds the TopicManager lock and wanted this mutex second: the two waited on
/// each other for ever (a nodelet run hung at its start, 1 in ~5 with traction; gdb: LockstepDriver::run
/// in TopicManager::publish, TorqueController::compute in InlineCallbackQueue::addCallback). Now only a
/// Hold waits for the mutex, and a Hold is never taken under roscpp's locks.
class DeferringInlineQueue : public ros::CallbackQueueInterface {
 public:
  /// The mutex, held for a scope by a thread of the node's own (not a roscpp callback); on leaving the
  /// scope it runs what was queued meanwhile.
  class Hold {
   public:
    explicit Hold(DeferringInlineQueue& q) : q_(q) { q_.mutex_.lock(); }
    ~Hold() {
      q_.mutex_.unlock();
      q_.drain();
    }
    Hold(const Hold&) = delete;
    Hold& operator=(const Hold&) = delete;

   private:
    DeferringInlineQueue& q_;
  };

  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t /*owner_id*/) override {
    {
      std::lock_guard<std::mutex> lock(pending_mutex_);
      pending_.push_back(callback);
    }
    drain();
  }
  void removeByID(uint64_t /*owner_id*/) override {}

 private:
  /// Runs the queued callbacks while the mutex can be had at once; a holder that lets go drains again, so
  /// a callback queued while it held the mutex is not left behind.
  void drain() {
    for (;;) {
      std::unique_lock<std::recursive_mutex> lock(mutex_, std::try_to_lock);
      if (!lock.owns_lock()) return;  // its holder drains when it lets go
      ros::CallbackInterfacePtr next;
      {
        std::lock_guard<std::mutex> pending_lock(pending_mutex_);
        if (pending_.empty()) return;
        next = pending_.front();
        pending_.pop_front();
      }
      // As InlineCallbackQueue: a callback that is not ready (its owner gone) is dropped.
      if (next->ready()) next->call();
    }
  }

  std::recursive_mutex mutex_;
  std::mutex pending_mutex_;
  std::deque<ros::CallbackInterfacePtr> pending_;
};

}  // namespace sowing_robot
