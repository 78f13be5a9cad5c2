#include "sowing_robot/ros/common/ready_roster.h"

#include <utility>

namespace sowing_robot {

std::string announcedName(const ros::NodeHandle& pnh) {
  const std::string& ns = pnh.getNamespace();
  const std::size_t slash = ns.find_last_of('/');
  return slash == std::string::npos ? ns : ns.substr(slash + 1);
}

ReadyAnnouncer::ReadyAnnouncer(ros::NodeHandle nh, const ros::NodeHandle& pnh) {
  // Several publishers of one latched topic: a subscriber gets the last message of each of them.
  pub_ = nh.advertise<std_msgs::String>("ready", 1, true);
  std_msgs::String msg;
  msg.data = announcedName(pnh);
  pub_.publish(msg);
}

ReadyRoster::ReadyRoster(ros::NodeHandle nh, std::vector<std::string> expected) : expected_(std::move(expected)) {
  if (!expected_.empty()) sub_ = nh.subscribe("ready", 100, &ReadyRoster::announced, this);
}

void ReadyRoster::announced(const std_msgs::String::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  seen_.insert(msg->data);
}

bool ReadyRoster::complete() const { return missing().empty(); }

std::string ReadyRoster::missing() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::string out;
  for (const std::string& name : expected_)
    if (!seen_.count(name)) out += (out.empty() ? "" : " ") + name;
  return out;
}

}  // namespace sowing_robot
