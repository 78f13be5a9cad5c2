// The start-up handshake of a lockstep run. Every node of the loop announces itself on the latched topic
// `ready` (std_msgs/String: its base name) once its publishers exist and each of its per-period inputs is
// linked at a publisher (publisher_links.h: a subscription merely made can still lose the first messages);
// plant_sim takes step 0 only when every name of its `wait_for` list has announced (and its subscriber
// counts are met).
//
// Why names and not counts: in a nodelet manager the links of all nodelets to one topic count once, so
// plant_sim's subscriber count could not tell whether run_monitor or seed_drill had loaded yet. A short
// scenario then ran to its end before run_monitor existed, and the headless run never ended (seen in
// nodelet runs under load; the 2 s start-up delay only made it rarer). A latched topic with one publisher
// per node gives each announcement to the plant however late either side starts, and only from nodes
// that are alive.
#pragma once

#include <ros/ros.h>
#include <std_msgs/String.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace sowing_robot {

/// The base name a node announces: the last component of its private namespace ("/ns/seed_drill" ->
/// "seed_drill"), the same for a node and a nodelet of that name.
std::string announcedName(const ros::NodeHandle& pnh);

/// Held by a node for its lifetime: its announcement stays latched on `ready` while it lives.
class ReadyAnnouncer {
 public:
  ReadyAnnouncer();
  /// Call when the node's subscriptions and publishers are made (the end of its constructor). In
  /// lockstep it announces from a thread of its own once every one of `inputs` (its per-period
  /// subscriptions) is linked at a publisher, warning every 5 s, naming the topic, while one is not;
  /// otherwise (or without inputs) at once.
  ReadyAnnouncer(ros::NodeHandle nh, const ros::NodeHandle& pnh, bool lockstep = false,
                 const std::vector<ros::Subscriber>& inputs = {});
  ReadyAnnouncer(ReadyAnnouncer&&) noexcept;
  ReadyAnnouncer& operator=(ReadyAnnouncer&&) noexcept;
  ~ReadyAnnouncer();

 private:
  struct Waiting;
  std::unique_ptr<Waiting> waiting_;  // stops and joins the thread when the node goes
};

/// plant_sim's side: who has announced, against the names it waits for.
class ReadyRoster {
 public:
  ReadyRoster() = default;
  /// Subscribes to `ready` only when `expected` is not empty.
  ReadyRoster(ros::NodeHandle nh, std::vector<std::string> expected);
  bool complete() const;
  /// The expected names not announced yet, space-separated ("" when complete).
  std::string missing() const;

 private:
  void announced(const std_msgs::String::ConstPtr& msg);

  std::vector<std::string> expected_;
  mutable std::mutex mutex_;
  std::set<std::string> seen_;
  ros::Subscriber sub_;  // last: unsubscribed before the members its callback uses go
};

}  // namespace sowing_robot
