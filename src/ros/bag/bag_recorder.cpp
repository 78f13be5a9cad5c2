// The recorder's work (bag_recorder.h): options, subscriptions, throttling, the stamp order, the close.
//
// rosbag record subscribes with a fixed queue of 100 messages; a lockstep run does not wait for it, so
// on a loaded machine it drops whole blocks (measured: up to 241 of 25,001 tracking errors). This
// recorder subscribes with a large queue, and before the close it takes every message already received.
#include "sowing_robot/ros/bag/bag_recorder.h"

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosgraph_msgs/Log.h>
#include <std_msgs/Time.h>
#include <topic_tools/shape_shifter.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "sowing_robot/ros/bag/message_stamp.h"
#include "sowing_robot/ros/bag/stamp_order_writer.h"
#include "sowing_robot/ros/common/node_failure.h"
#include "sowing_robot/ros/common/param_reader.h"
#include "sowing_robot/ros/common/ready_roster.h"

namespace sowing_robot {
namespace {

std::vector<std::string> words(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream ss(text);
  for (std::string t; ss >> t;) out.push_back(t);
  return out;
}

/// Hands each received message to `target` after `delay`, on roscpp's network thread: with a delay
/// the recorder reads its connections slowly and the backlog stays with the publishers, as on a machine
/// that starves the recorder of CPU (the run whose last 2 s died with their publishers). Tests only.
class DelayingQueue : public ros::CallbackQueueInterface {
 public:
  DelayingQueue(ros::CallbackQueueInterface* target, double delay) : target_(target), delay_(delay) {}
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t owner_id) override {
    delay_.sleep();
    target_->addCallback(callback, owner_id);
  }
  void removeByID(uint64_t owner_id) override { target_->removeByID(owner_id); }

 private:
  ros::CallbackQueueInterface* target_;
  ros::WallDuration delay_;
};

/// The oldest of the newest header stamps received on the period topics: everything up to it is recorded
/// on every one of them (each topic's messages come in stamp order over one connection): in the bag, or in
/// deterministic mode held for the stamp order and written at the close at the latest.
class RecordedUntil {
 public:
  RecordedUntil(ros::NodeHandle& pnh, std::size_t topics)
      : newest_(topics), checked_(topics, false), pub_(pnh.advertise<std_msgs::Time>("recorded_until", 1, true)) {}

  /// A message of period topic `i`, stamped `stamp` if it carries one, was received (and written, or held
  /// for the stamp order: in the bag at the close either way).
  void received(std::size_t i, const std::string& topic, const topic_tools::ShapeShifter& msg, bool stamped,
                const ros::Time& stamp) {
    if (!checked_[i]) {
      checked_[i] = true;
      if (!startsWithHeader(msg.getMessageDefinition())) {
        ROS_ERROR("bag_recorder: period topic %s (%s) has no header first; not counted in recorded_until",
                  topic.c_str(), msg.getDataType().c_str());
        ignored_.push_back(i);
      }
    }
    if (std::find(ignored_.begin(), ignored_.end(), i) != ignored_.end() || !stamped) return;
    newest_[i] = std::max(newest_[i], stamp);
    ros::Time oldest = ros::TIME_MAX;
    for (std::size_t k = 0; k < newest_.size(); ++k)
      if (std::find(ignored_.begin(), ignored_.end(), k) == ignored_.end()) oldest = std::min(oldest, newest_[k]);
    if (oldest != ros::TIME_MAX && oldest > published_.data) {
      published_.data = oldest;
      pub_.publish(published_);
    }
  }
  const ros::Time& until() const { return published_.data; }

 private:
  std::vector<ros::Time> newest_;  // zero until the topic's first message
  std::vector<bool> checked_;
  std::vector<std::size_t> ignored_;
  std_msgs::Time published_;
  ros::Publisher pub_;
};

struct Options {
  std::string output;
  std::vector<std::string> topics, period_topics, throttle_topics;
  int queue = 200000;
  double throttle_period = 0.1;  // [s] of the throttled topics' stamps
  int min_log_level = 0;         // rosgraph_msgs/Log levels: 1 debug, 2 info, 4 warn, 8 error, 16 fatal
  std::string compression = "none";
  double receive_delay = 0.0;
  bool deterministic = false;
  double reorder_window = 5.0;  // [s] simulated
};

/// Reads and checks the private parameters; throws badParameter (node_failure.h) on the first problem.
Options readOptions(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) {
  ParamReader p(pnh);
  Options o;
  o.output = p.get("output", "");
  // Resolved in the node's namespace (a fleet's robot_<i>/ records its own topics), and kept so in the bag.
  o.topics = words(p.get("topics", ""));
  o.period_topics = words(p.get("period_topics", ""));
  o.throttle_topics = words(p.get("throttle_topics", ""));
  for (auto* list : {&o.topics, &o.period_topics, &o.throttle_topics})
    for (std::string& t : *list) t = nh.resolveName(t);
  o.queue = p.get("queue", o.queue);
  o.receive_delay = p.get("receive_delay", o.receive_delay);
  o.deterministic = p.get("deterministic", o.deterministic);
  o.reorder_window = p.get("reorder_window", o.reorder_window);
  o.throttle_period = p.get("throttle_period", o.throttle_period);
  o.min_log_level = p.get("min_log_level", o.min_log_level);
  o.compression = p.get("compression", o.compression);
  if (!p.error().empty()) refuseToStart(p.error());
  const std::string unknown = p.unknownKeys();
  if (!unknown.empty()) refuseToStart(unknown);
  if (o.output.empty() || o.topics.empty() || o.queue < 1) {
    refuseToStart("~output (a path) and ~topics (space-separated) are required, ~queue >= 1 (got output '" + o.output +
                  "', " + std::to_string(o.topics.size()) + " topics, queue " + std::to_string(o.queue) + ")");
  }
  if (!(o.reorder_window > 0.0 && o.reorder_window <= 600.0))
    refuseToStart("~reorder_window = " + std::to_string(o.reorder_window) + " must be in (0, 600] s");
  if (!(o.receive_delay >= 0.0 && o.receive_delay < 1.0))
    refuseToStart("~receive_delay = " + std::to_string(o.receive_delay) + " must be in [0, 1) s");
  for (const std::string& t : o.period_topics)
    if (std::find(o.topics.begin(), o.topics.end(), t) == o.topics.end())
      refuseToStart("~period_topics: " + t + " is not among ~topics");
  for (const std::string& t : o.throttle_topics)
    if (std::find(o.topics.begin(), o.topics.end(), t) == o.topics.end())
      refuseToStart("~throttle_topics: " + t + " is not among ~topics");
  if (!(o.throttle_period >= 1e-6 && o.throttle_period <= 3600.0))
    refuseToStart("~throttle_period = " + std::to_string(o.throttle_period) + " must be in [1e-6, 3600] s");
  if (o.min_log_level < 0 || o.min_log_level > 16)
    refuseToStart("~min_log_level = " + std::to_string(o.min_log_level) + " must be in [0, 16]");
  if (o.compression != "none" && o.compression != "lz4" && o.compression != "bz2")
    refuseToStart("~compression = '" + o.compression + "' must be none, lz4 or bz2");
  return o;
}

using MessageEvent = ros::MessageEvent<topic_tools::ShapeShifter const>;

/// One recorded topic: whether it is a period topic (number `period_index`) and, if throttled, the period of
/// stamps whose first message was written last.
struct TopicState {
  std::string topic;
  bool is_period = false;
  std::size_t period_index = 0;
  bool throttled = false;
  std::int64_t last_bucket = -1;
};

/// What every topic's callback writes to and counts: the bag directly, or (~deterministic) the stamp-order
/// writer, which holds each message ~reorder_window behind ~recorded_until.
struct Recording {
  Recording(rosbag::Bag& bag, const Options& o, RecordedUntil& recorded)
      : bag(bag),
        o(o),
        recorded(recorded),
        ordered(bag, o.topics),
        window(o.reorder_window),
        throttle_ns(std::max<std::int64_t>(1, std::llround(o.throttle_period * 1e9))) {}
  rosbag::Bag& bag;
  const Options& o;
  RecordedUntil& recorded;
  std::size_t received = 0;
  std::size_t written = 0;   // written to the bag (the stamp-order writer counts its own)
  StampOrderWriter ordered;  // ~deterministic only
  const ros::Duration window;
  std::unordered_set<std::string> warned;  // topics already warned of
  const std::int64_t throttle_ns;
  std::vector<TopicState> states;  // one per ~topics entry, filled before any subscription
};

/// False when the lean recording leaves `msg` out: a throttled topic's message whose stamp lies in the period
/// already written, or a log line below ~min_log_level. `stamp`/`stamped`: the message's, if read.
bool keep(Recording& rec, TopicState& state, const topic_tools::ShapeShifter& msg, bool stamped,
          const ros::Time& stamp) {
  if (rec.o.min_log_level > 0 && msg.getDataType() == "rosgraph_msgs/Log")
    return msg.instantiate<rosgraph_msgs::Log>()->level >= rec.o.min_log_level;
  if (!state.throttled) return true;
  if (!stamped) {
    if (rec.warned.insert(state.topic + " unthrottled").second)
      ROS_WARN("bag_recorder: %s (%s) carries no stamp: recorded unthrottled", state.topic.c_str(),
               msg.getDataType().c_str());
    return true;
  }
  const std::int64_t bucket = static_cast<std::int64_t>(stamp.toNSec()) / rec.throttle_ns;
  if (bucket <= state.last_bucket) return false;  // repeats and late ones of a written period too
  state.last_bucket = bucket;
  return true;
}

/// Deterministic mode: `bytes` of `msg` (stamped `stamp` if `stamped`) to the stamp-order writer.
void addInStampOrder(Recording& rec, const std::string& topic, const topic_tools::ShapeShifter& msg, bool stamped,
                     const ros::Time& stamp, std::vector<std::uint8_t>&& bytes, const MessageEvent& event) {
  ros::Time t = stamped ? stamp : ros::Time::now();
  if (t < ros::TIME_MIN) t = ros::TIME_MIN;  // a stamp of 0
  if (!stamped && rec.warned.insert(topic).second)
    ROS_WARN(
        "bag_recorder: %s (%s) carries no stamp: recorded at its receive time, so the bag will not "
        "repeat bit for bit",
        topic.c_str(), msg.getDataType().c_str());
  const ros::Time written_up_to = rec.ordered.writtenUpTo();
  if (!rec.ordered.add(topic, t, std::move(bytes), event.getConnectionHeaderPtr()) &&
      rec.warned.insert(topic + " late").second)
    ROS_WARN(
        "bag_recorder: %s stamped %.3f s came after the bag was written to %.3f s (~reorder_window "
        "%.1f s): written out of order, so the bag will not repeat bit for bit",
        topic.c_str(), t.toSec(), written_up_to.toSec(), rec.window.toSec());
}

/// A message of `state.topic` received: written, held, or (lean recording) left out.
void recordMessage(Recording& rec, TopicState& state, const MessageEvent& event) {
  const std::string& topic = state.topic;
  const bool is_period = state.is_period;
  const topic_tools::ShapeShifter& msg = *event.getMessage();
  ros::Time stamp;
  bool stamped = false;
  ++rec.received;
  if (!rec.o.deterministic) {
    stamped = (is_period || state.throttled) && messageStamp(msg, stamp);
    if (keep(rec, state, msg, stamped, stamp)) {
      ros::Time t = ros::Time::now();
      if (t < ros::TIME_MIN) t = ros::TIME_MIN;  // before the first /clock
      rec.bag.write(topic, t, event.getMessage(), event.getConnectionHeaderPtr());
      ++rec.written;
    }
  } else {
    std::vector<std::uint8_t> bytes(msg.size());  // held by the writer; the stamp is read from them
    ros::serialization::OStream to(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
    msg.write(to);
    stamped = messageStamp(msg, bytes, stamp);
    if (keep(rec, state, msg, stamped, stamp))
      addInStampOrder(rec, topic, msg, stamped, stamp, std::move(bytes), event);
  }
  if (is_period) rec.recorded.received(state.period_index, topic, msg, stamped, stamp);
  if (rec.o.deterministic && rec.recorded.until() > ros::TIME_MIN + rec.window)
    rec.ordered.writeBefore(rec.recorded.until() - rec.window);
}

/// One subscriber per topic into `rec`, on `delaying` when ~receive_delay is set; the period topics' own
/// subscribers are also put in `period_subs`.
std::vector<ros::Subscriber> subscribeAll(ros::NodeHandle& nh, Recording& rec, DelayingQueue& delaying,
                                          std::vector<ros::Subscriber>& period_subs) {
  const Options& o = rec.o;
  std::vector<ros::Subscriber> subs;
  rec.states.resize(o.topics.size());  // not resized again: the callbacks hold references
  for (std::size_t i = 0; i < o.topics.size(); ++i) {
    const std::string& topic = o.topics[i];
    const auto period = std::find(o.period_topics.begin(), o.period_topics.end(), topic);
    TopicState& state = rec.states[i];
    state.topic = topic;
    state.period_index = static_cast<std::size_t>(period - o.period_topics.begin());
    state.is_period = period != o.period_topics.end();
    state.throttled = std::find(o.throttle_topics.begin(), o.throttle_topics.end(), topic) != o.throttle_topics.end();
    const bool is_period = state.is_period;
    boost::function<void(const MessageEvent&)> cb = [&rec, &state](const MessageEvent& event) {
      recordMessage(rec, state, event);
    };
    ros::SubscribeOptions so;
    so.initByFullCallbackType<const MessageEvent&>(topic, static_cast<std::uint32_t>(o.queue), cb);
    so.transport_hints = ros::TransportHints().tcpNoDelay();
    if (o.receive_delay > 0.0) so.callback_queue = &delaying;
    subs.push_back(nh.subscribe(so));
    if (is_period) period_subs.push_back(subs.back());
  }
  return subs;
}

/// Writes what is held, closes the bag and gives it its name; false if it could not be renamed.
bool closeBag(Recording& rec, const std::string& active) {
  const Options& o = rec.o;
  std::string order;
  if (o.deterministic) {
    rec.ordered.writeAll();
    const StampOrderWriter::Counts& c = rec.ordered.counts();
    order = " in stamp order (" + std::to_string(c.repeats) + " resent kept once, " + std::to_string(c.late) + " late)";
  }
  if (!o.throttle_topics.empty() || o.min_log_level > 0) order += " of " + std::to_string(rec.received) + " received";
  rec.bag.close();
  if (std::rename(active.c_str(), o.output.c_str()) != 0) {
    ROS_ERROR("bag_recorder: could not rename %s to %s", active.c_str(), o.output.c_str());
    return false;
  }
  std::printf("bag_recorder: %zu messages written to %s%s\n",
              o.deterministic ? rec.ordered.counts().written : rec.written, o.output.c_str(), order.c_str());
  std::fflush(stdout);
  return true;
}

}  // namespace

struct BagRecorder::Impl {
  Impl(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : o(readOptions(nh, pnh)) {}
  Options o;
  rosbag::Bag bag;
  std::string active;
  std::unique_ptr<RecordedUntil> recorded;
  std::unique_ptr<DelayingQueue> delaying;
  std::unique_ptr<Recording> rec;
  std::vector<ros::Subscriber> subs, period_subs;
  ReadyAnnouncer ready;
  bool closed = false;
};

BagRecorder::BagRecorder(ros::NodeHandle nh, ros::NodeHandle pnh) : impl_(std::make_unique<Impl>(nh, pnh)) {
  Impl& m = *impl_;
  const Options& o = m.o;
  m.active = o.output + ".active";
  try {
    m.bag.open(m.active, rosbag::bagmode::Write);
    if (o.compression != "none")
      m.bag.setCompression(o.compression == "lz4" ? rosbag::compression::LZ4 : rosbag::compression::BZ2);
  } catch (const rosbag::BagException& e) {
    throw badParameter("cannot open " + m.active + ": " + e.what());
  }
  m.recorded = std::make_unique<RecordedUntil>(pnh, o.period_topics.size());
  m.delaying = std::make_unique<DelayingQueue>(nh.getCallbackQueue(), o.receive_delay);
  m.rec = std::make_unique<Recording>(m.bag, o, *m.recorded);
  m.subs = subscribeAll(nh, *m.rec, *m.delaying, m.period_subs);
  // plant_sim's wait_for may name the recorder: announced once the per-period topics are linked, so none of
  // their first messages is lost
  m.ready = ReadyAnnouncer(nh, pnh, true, m.period_subs);
  ROS_INFO(
      "bag_recorder: recording %zu topics (%zu of them one message per %.3f s of stamps, compression %s) to %s%s",
      o.topics.size(), o.throttle_topics.size(), o.throttle_period, o.compression.c_str(), o.output.c_str(),
      o.receive_delay > 0.0 ? (" (receive_delay " + std::to_string(o.receive_delay) + " s per message)").c_str() : "");
}

BagRecorder::~BagRecorder() {
  if (impl_->closed) return;
  try {
    close();
  } catch (const std::exception& e) {  // rosbag's errors: a destructor must not throw
    ROS_ERROR("bag_recorder: closing %s failed: %s", impl_->active.c_str(), e.what());
  }
}

void BagRecorder::stopReceiving() { impl_->subs.clear(); }

std::size_t BagRecorder::received() const { return impl_->rec->received; }

bool BagRecorder::close() {
  Impl& m = *impl_;
  m.closed = true;
  // Every copy of a subscriber goes: the last one's unsubscribe waits for a callback still running (a nodelet's,
  // on the shared thread) and drops the ones queued, so nothing writes to the bag while it is closed.
  m.subs.clear();
  m.period_subs.clear();
  m.ready = ReadyAnnouncer();
  return closeBag(*m.rec, m.active);
}

}  // namespace sowing_robot
