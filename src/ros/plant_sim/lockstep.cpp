#include "sowing_robot/ros/plant_sim/lockstep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>

#include "sowing_robot/ros/common/node_failure.h"
#include "sowing_robot/ros/common/publisher_links.h"

namespace sowing_robot {

LockstepDriver::LockstepDriver(ros::NodeHandle nh, SimulatedPlant& plant, const Config& config)
    : plant_(plant),
      cfg_(config),
      protocol_(plant.periodNs(), core::lockstepLastStep(config.duration, plant.periodNs()), config.timing),
      roster_(nh, config.wait_for) {
  torque_sub_ = subscribeTorque(nh, &queue_, [this](const WheelTorque::ConstPtr& m) { torqueCallback(m); });
}

LockstepDriver::~LockstepDriver() {
  // Returns only when no torque callback is running: roscpp holds the subscription's callback lock
  // while a callback queued on queue_ runs. Not under queue_'s mutex (that order would be the reverse
  // of roscpp's and could deadlock).
  torque_sub_.shutdown();
}

void LockstepDriver::publishStep(std::int64_t k) {
  const bool last = k == protocol_.lastStep();
  // The end-of-run report goes out before the final state, which no step follows: once that state is out,
  // run_monitor may end the run at any moment (as nodelets it ends the whole manager, and a report made
  // when the last torque came back was lost with it, 1 run in a few).
  if (last) reportFinished();
  plant_.publish(k, plant_.visualStep(k) || last);
}

void LockstepDriver::torqueCallback(const WheelTorque::ConstPtr& msg) {
  using Answer = core::LockstepProtocol::Answer;
  const std::int64_t stamp = static_cast<std::int64_t>(msg->header.stamp.toNSec());
  switch (protocol_.onTorque(stamp, {msg->right, msg->left})) {
    case Answer::kStep:
      plant_.setToolRaised(msg->tool_raised);  // the answer to this state: its torque and its hitch command
      plant_.setToolDepth(msg->tool_depth);    // and its depth control's depth
      if (!plant_.step(protocol_.torque(), msg->header.stamp)) {
        protocol_.diverged();  // run() reports it; the bad state is never published
        return;
      }
      publishStep(protocol_.awaited());
      return;
    case Answer::kFinish:  // the answer to the final state: reported when that state went out (publishStep)
      return;
    case Answer::kLate:
      ROS_WARN_THROTTLE(1.0, "plant_sim: late wheel torque for t=%.6f while at t=%.6f ignored (%ld so far)",
                        msg->header.stamp.toSec(), 1e-9 * protocol_.stampOf(protocol_.awaited()), protocol_.late());
      return;
    case Answer::kNonFinite:
      ROS_WARN_THROTTLE(1.0, "plant_sim: rejected non-finite wheel torque (right %f, left %f); %ld so far", msg->right,
                        msg->left, protocol_.nonFinite());
      return;
    case Answer::kRepeat:  // a re-sent state answered twice: the first answer was used
    case Answer::kAhead:
    case Answer::kNotRunning: return;
  }
}

void LockstepDriver::reportFinished() {
  const double wall = ros::WallTime::now().toSec() - protocol_.startedAt();
  const std::string repeats =
      protocol_.repeats() > 0 ? "; " + std::to_string(protocol_.repeats()) + " repeated answers ignored" : "";
  ROS_INFO(
      "plant_sim: lockstep scenario finished: %.3f s simulated in %.3f s wall (real-time factor %.2f); "
      "%ld late and %ld non-finite torques ignored%s",
      cfg_.duration, wall, wall > 0 ? cfg_.duration / wall : 0.0, protocol_.late(), protocol_.nonFinite(),
      repeats.c_str());
  plant_.reportContacts();
}

unsigned LockstepDriver::stateSubscribers() const {
  return plant_.truthSubscribers() + (cfg_.loop_on_odom ? plant_.odomSubscribers() : 0u);
}

bool LockstepDriver::loopConnected() const {
  // The torque link asked of its publisher, last (it costs calls to the master): publisher_links.h.
  return static_cast<int>(stateSubscribers()) >= cfg_.min_subscribers && torque_sub_.getNumPublishers() >= 1 &&
         plant_.inputsReady() && roster_.complete() && firstUnlinkedTopic({torque_sub_.getTopic()}).empty();
}

std::string LockstepDriver::torqueSources() const {
  const unsigned publishers = torque_sub_.getNumPublishers();
  return std::to_string(publishers) + " publisher(s) on " + torque_sub_.getTopic() +
         (publishers == 0 ? ": is torque_controller running?" : "");
}

void LockstepDriver::report(const core::LockstepProtocol::Supervision& s) const {
  if (s.step < 0) {
    const std::string model = plant_.model().waitingFor();
    ROS_WARN(
        "plant_sim: lockstep waiting for the loop for %.1f s wall: %u/%d %s subscribers, %u wheel_torque "
        "publishers, not announced on ready: %s%s%s",
        s.waited, stateSubscribers(), cfg_.min_subscribers, cfg_.loop_on_odom ? "ground_truth + odom" : "ground_truth",
        torque_sub_.getNumPublishers(), roster_.missing().empty() ? "none" : roster_.missing().c_str(),
        model.empty() ? "" : ", waiting for ", model.c_str());
  } else {
    ROS_ERROR(
        "plant_sim: lockstep stalled at t=%.6f s: no wheel_torque stamped for it after %.1f s wall (%s); "
        "waiting",
        plant_.stampOf(s.step).toSec(), s.waited, torqueSources().c_str());
  }
}

std::string LockstepDriver::giveUpReason(const core::LockstepProtocol::Supervision& s) const {
  const std::string missing = roster_.missing();
  const std::string what = s.step < 0 ? "the loop to connect (state subscribers, a wheel_torque publisher" +
                                            (missing.empty() ? std::string(")") : "; not announced: " + missing + ")")
                                      : "a wheel_torque stamped for the current state";
  char text[200];
  std::snprintf(text, sizeof text, "lockstep gave up at t=%.6f s after %.1f s wall (lockstep_give_up) waiting for ",
                s.step < 0 ? 0.0 : plant_.stampOf(s.step).toSec(), cfg_.timing.give_up);
  return text + what + "; " + torqueSources();
}

void LockstepDriver::run() {
  // The loop needs this thread only when an answer is missing, so it looks every 10 ms.
  const ros::WallDuration poll(std::min(0.01, cfg_.timing.retry));
  bool started = false;
  while (ros::ok() && !stop_) {
    // Counted outside the lock (roscpp's own locks), and only until step 0: the protocol ignores it after.
    const bool connected = started || loopConnected();
    const double now = ros::WallTime::now().toSec();
    core::LockstepProtocol::Supervision s;
    bool over = false;
    {
      DeferringInlineQueue::Hold hold(queue_);
      s = protocol_.tick(now, connected);
      if (s.start) {
        publishStep(0);  // from here on the torque callback drives the steps
      } else if (s.resend) {
        // A connection that came late gets the state again, and /clock with it: the reference generator,
        // paced by /clock, may be what the loop waits for (a reference generator that started late).
        plant_.publish(s.step, false, true);
      }
      over = protocol_.over();
    }
    started = started || s.start;
    if (s.report) report(s);
    if (s.give_up) throw NodeFailure(ExitCode::kGaveUp, giveUpReason(s));
    if (over) break;
    poll.sleep();
  }
  DeferringInlineQueue::Hold hold(queue_);
  if (protocol_.phase() == core::LockstepProtocol::Phase::kDiverged)
    throw NodeFailure(ExitCode::kDiverged, plant_.divergence());
}

}  // namespace sowing_robot
