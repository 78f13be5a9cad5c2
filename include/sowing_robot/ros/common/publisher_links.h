// Whether a subscription is connected, as its publisher sees it.
//
// A subscriber's own count (ros::Subscriber::getNumPublishers) grows when it has sent its connection
// header, before the publisher has read that header and added the link: a message published in between
// goes nowhere. In a lockstep run that was the first seconds of a topic lost to a tester or recorder that
// had subscribed "in time" (fused_field_nodelets: 3119 of 8001 estimates received), or a fix lost to the
// state_estimator, which then waited for it and gave up. A publisher lists a link in its slave API
// getBusInfo from the moment it adds it, so once every input of a node is listed there, every message
// published after reaches the node: what ReadyAnnouncer waits for before announcing (ready_roster.h).
#pragma once

#include <ros/ros.h>

#include <string>
#include <vector>

namespace sowing_robot {

/// The nodes every publisher of `topic` (a resolved name) lists as linked to it, as the master and the
/// publishers answer now: a node once per link (a nodelet manager's nodelets share one).
std::vector<std::string> linkedSubscribers(const std::string& topic);

/// The first of `topics` (resolved names) that no publisher has linked to this process yet: asked of
/// every publisher the master lists for it. "" when each has at least one publisher holding this
/// process's link. A topic with no publisher yet, or one whose publisher does not answer, is unlinked.
std::string firstUnlinkedTopic(const std::vector<std::string>& topics);

/// The resolved topics of `subscribers` (what firstUnlinkedTopic takes).
std::vector<std::string> topicsOf(const std::vector<ros::Subscriber>& subscribers);

/// Waits (wall time, polling every 10 ms) until firstUnlinkedTopic(topics) is "": true, or false after
/// `timeout` s or on shutdown, with the topic still unlinked in `*unlinked`.
bool waitUntilLinked(const std::vector<std::string>& topics, double timeout, std::string* unlinked);

}  // namespace sowing_robot
