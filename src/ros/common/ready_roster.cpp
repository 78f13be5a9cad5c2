#include "sowing_robot/ros/common/ready_roster.h"

#include <utility>

#include "sowing_robot/ros/common/publisher_links.h"

namespace sowing_robot {

std::string announcedName(const ros::NodeHandle& pnh) {
  const std::string& ns = pnh.getNamespace();
  const std::size_t slash = ns.find_last_of('/');
  return slash == std::string::npos ? ns : ns.substr(slash + 1);
}

struct ReadyAnnouncer::Waiting {
  ros::Publisher pub;
  std_msgs::String name;
  std::atomic<bool> stop{false};
  std::thread thread;

  ~Waiting() {
    stop = true;
    if (thread.joinable()) thread.join();
  }

  /// Polls the links every 10 ms, then announces once (the latched message stays).
  void announceWhenLinked(const std::vector<std::string>& topics) {
    const ros::WallTime start = ros::WallTime::now();
    double warned = 0.0;
    while (!stop && ros::ok()) {
      const std::string unlinked = firstUnlinkedTopic(topics);
      if (unlinked.empty()) {
        pub.publish(name);
        return;
      }
      const double waited = (ros::WallTime::now() - start).toSec();
      if (waited - warned >= 5.0) {
        warned = waited;
        ROS_WARN("%s: not announcing ready after %.0f s: no publisher of %s has linked it yet (is it running?)",
                 name.data.c_str(), waited, unlinked.c_str());
      }
      ros::WallDuration(0.01).sleep();
    }
  }
};

ReadyAnnouncer::ReadyAnnouncer() = default;
ReadyAnnouncer::ReadyAnnouncer(ReadyAnnouncer&&) noexcept = default;
ReadyAnnouncer& ReadyAnnouncer::operator=(ReadyAnnouncer&&) noexcept = default;
ReadyAnnouncer::~ReadyAnnouncer() = default;

ReadyAnnouncer::ReadyAnnouncer(ros::NodeHandle nh, const ros::NodeHandle& pnh, bool lockstep,
                               const std::vector<ros::Subscriber>& inputs)
    : waiting_(std::make_unique<Waiting>()) {
  // Several publishers of one latched topic: a subscriber gets the last message of each of them.
  waiting_->pub = nh.advertise<std_msgs::String>("ready", 1, true);
  waiting_->name.data = announcedName(pnh);
  if (!lockstep || inputs.empty()) {
    waiting_->pub.publish(waiting_->name);
    return;
  }
  waiting_->thread = std::thread(&Waiting::announceWhenLinked, waiting_.get(), topicsOf(inputs));
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
