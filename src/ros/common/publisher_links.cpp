#include "sowing_robot/ros/common/publisher_links.h"

#include <ros/master.h>
#include <ros/network.h>
#include <ros/this_node.h>
#include <ros/xmlrpc_manager.h>

#include <algorithm>
#include <map>

namespace sowing_robot {
namespace {

const double kAnswerTimeout = 1.0;  // [s] a publisher's answer to getBusInfo

/// An XML-RPC client whose call gives up after a timeout (XmlRpcClient::execute waits for ever): a node that
/// accepts the connection but never answers (a stopped process) must not hang plant_sim's lockstep thread,
/// which asks before step 0, nor a node's announcer.
class BoundedClient : public XmlRpc::XmlRpcClient {
 public:
  BoundedClient(const std::string& host, int port) : XmlRpcClient(host.c_str(), port, "/") {}
  ~BoundedClient() override { close(); }

  bool call(const char* method, const XmlRpc::XmlRpcValue& params, XmlRpc::XmlRpcValue& result, double timeout) {
    if (!setupConnection() || !generateRequest(method, params)) return false;
    _disp.work(timeout);  // returns once the answer is read (the client leaves the dispatcher) or at the timeout
    return _connectionState == IDLE && parseResponse(result);
  }
};

/// The master's publishers (getSystemState): per topic, the nodes that publish it. Empty when it does not
/// answer, or answers in another shape.
std::map<std::string, std::vector<std::string>> publishersByTopic() {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  std::map<std::string, std::vector<std::string>> out;
  if (!ros::master::execute("getSystemState", request, response, payload, false)) return out;
  try {
    XmlRpc::XmlRpcValue& publishers = payload[0];
    for (int i = 0; i < publishers.size(); ++i) {
      std::vector<std::string>& nodes = out[static_cast<std::string>(publishers[i][0])];
      for (int j = 0; j < publishers[i][1].size(); ++j) nodes.push_back(publishers[i][1][j]);
    }
  } catch (const XmlRpc::XmlRpcException&) {
    out.clear();
  }
  return out;
}

/// The destinations of node `publisher`'s outgoing links on `topic` (slave API getBusInfo: [id, destination,
/// direction, transport, topic, connected, ...] per link); none when it does not answer.
void linksOf(const std::string& publisher, const std::string& topic, std::vector<std::string>& out) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  request[1] = publisher;
  if (!ros::master::execute("lookupNode", request, response, payload, false)) return;
  std::string host;
  std::uint32_t port = 0;
  const std::string uri = payload;
  if (!ros::network::splitURI(uri, host, port)) return;
  BoundedClient client(host, static_cast<int>(port));
  XmlRpc::XmlRpcValue args, result, info;
  args[0] = ros::this_node::getName();
  if (!client.call("getBusInfo", args, result, kAnswerTimeout) ||
      !ros::XMLRPCManager::instance()->validateXmlrpcResponse("getBusInfo", result, info))
    return;
  for (int i = 0; i < info.size(); ++i) {
    XmlRpc::XmlRpcValue& link = info[i];
    if (link.size() >= 5 && static_cast<std::string>(link[2]) == "o" && static_cast<std::string>(link[4]) == topic)
      out.push_back(link[1]);
  }
}

/// linkedSubscribers with the master's publishers asked once by the caller.
std::vector<std::string> linkedSubscribers(const std::string& topic,
                                           const std::map<std::string, std::vector<std::string>>& publishers) {
  std::vector<std::string> out;
  const auto nodes = publishers.find(topic);
  if (nodes == publishers.end()) return out;
  try {
    for (const std::string& publisher : nodes->second) linksOf(publisher, topic, out);
  } catch (const XmlRpc::XmlRpcException&) {  // an answer of another shape: what was read so far
  }
  return out;
}

}  // namespace

std::vector<std::string> linkedSubscribers(const std::string& topic) {
  return linkedSubscribers(topic, publishersByTopic());
}

std::string firstUnlinkedTopic(const std::vector<std::string>& topics) {
  const std::map<std::string, std::vector<std::string>> publishers = publishersByTopic();
  for (const std::string& topic : topics) {
    const std::vector<std::string> linked = linkedSubscribers(topic, publishers);
    if (std::find(linked.begin(), linked.end(), ros::this_node::getName()) == linked.end()) return topic;
  }
  return "";
}

std::vector<std::string> topicsOf(const std::vector<ros::Subscriber>& subscribers) {
  std::vector<std::string> out;
  for (const ros::Subscriber& s : subscribers)
    if (s) out.push_back(s.getTopic());
  return out;
}

bool waitUntilLinked(const std::vector<std::string>& topics, double timeout, std::string* unlinked) {
  const ros::WallTime start = ros::WallTime::now();
  for (;;) {
    *unlinked = firstUnlinkedTopic(topics);
    if (unlinked->empty()) return true;
    if (!ros::ok() || (ros::WallTime::now() - start).toSec() > timeout) return false;
    ros::WallDuration(0.01).sleep();
  }
}

}  // namespace sowing_robot
