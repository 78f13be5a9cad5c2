#include "sowing_robot/seed_map/bag_seeds.h"

#include <ros/message_traits.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <exception>
#include <set>

#include "sowing_robot/ros/common/seed_message.h"

namespace sowing_robot {
namespace seed_map {

std::string readBagSeeds(const std::string& path, const std::string& topic, std::vector<core::Seed>& seeds,
                         std::string& used_topic) {
  const std::string type = ros::message_traits::DataType<sowing_robot::Seed>::value();
  // The topic as given or resolved from the root (the bag holds resolved names: /seeds/record, /robot_0/...).
  const std::string wanted = topic.empty() || topic[0] == '/' ? topic : "/" + topic;
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    rosbag::View all(bag);
    std::set<std::string> topics, of_type;
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      topics.insert(c->topic);
      if (c->datatype == type) of_type.insert(c->topic);
    }
    std::string chosen;
    if (!wanted.empty()) {
      if (!topics.count(wanted)) return "no topic " + wanted + " in " + path;
      if (!of_type.count(wanted)) return wanted + " in " + path + " is not of type " + type;
      chosen = wanted;
    } else if (of_type.empty()) {
      return "no seeds in " + path + ": no topic of type " + type +
             " (sim.launch record:=true records the seed drill's seeds/record)";
    } else if (of_type.size() > 1) {
      std::string names;
      for (const std::string& t : of_type) names += (names.empty() ? "" : ", ") + t;
      return path + " holds seeds on several topics (" + names + "): choose one with --topic";
    } else {
      chosen = *of_type.begin();
    }
    std::vector<core::Seed> out;
    rosbag::View view(bag, rosbag::TopicQuery(chosen));
    for (const rosbag::MessageInstance& m : view) {
      const sowing_robot::Seed::ConstPtr msg = m.instantiate<sowing_robot::Seed>();
      if (!msg)
        return chosen + " in " + path + " holds another definition of " + type + " (md5sum " + m.getMD5Sum() + ")";
      out.push_back(seedOf(*msg));
    }
    if (out.empty()) return "no seeds in " + path + " on " + chosen;
    seeds = std::move(out);
    used_topic = chosen;
    return "";
  } catch (const std::exception& e) {
    // rosbag's exceptions (a missing, truncated or unindexed bag) and a message that does not deserialise.
    return "cannot read bag " + path + ": " + e.what();
  }
}

}  // namespace seed_map
}  // namespace sowing_robot
