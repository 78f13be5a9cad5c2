// plant_sim's lockstep driver: publish the state at t_k and step only when the wheel torque stamped t_k
// has come. The protocol's decisions are core::LockstepProtocol's; this class only moves messages:
// torques in, states out, and the protocol's reports as log lines.
//
// Threads: the wheel_torque callback runs inline where the torque is received (roscpp's network thread,
// or in a nodelet manager the thread that published it) and steps the plant and publishes the next
// state there, with no hand-over between threads. run()'s thread only supervises: it starts the run,
// re-sends a state nobody answered, reports a stall, gives up. Both hold queue_'s mutex while they
// touch the protocol or the plant; a torque that comes while run()'s thread holds it is run by that
// thread when it lets go (DeferringInlineQueue: waiting for it there could deadlock a nodelet run).
#pragma once

#include <ros/ros.h>

#include <atomic>
#include <string>

#include "sowing_robot/WheelTorque.h"
#include "sowing_robot/core/simulation/lockstep.h"
#include "sowing_robot/ros/common/deferring_callback_queue.h"
#include "sowing_robot/ros/common/ready_roster.h"
#include "sowing_robot/ros/plant_sim/driver.h"
#include "sowing_robot/ros/plant_sim/simulated_plant.h"

namespace sowing_robot {

class LockstepDriver : public PlantSimDriver {
 public:
  struct Config {
    core::LockstepTiming timing;
    double duration = 25.0;     // [s] sim; <= 0 runs forever
    int min_subscribers = 3;    // subscribers of ground_truth (+ odom with loop_on_odom) to wait for before step 0
    bool loop_on_odom = false;  // the controllers' feedback comes from odom (the encoders), not ground_truth
    std::vector<std::string> wait_for;  // and the nodes that must have announced on `ready` (ready_roster.h)
  };
  LockstepDriver(ros::NodeHandle nh, SimulatedPlant& plant, const Config& config);
  /// Unsubscribes first: returns only when no torque callback is running.
  ~LockstepDriver() override;
  /// Supervises the run until its end, shutdown or stop(). Throws NodeFailure: kDiverged (the state went
  /// bad in a torque callback, which stopped stepping at once) or kGaveUp (lockstep_give_up).
  void run() override;
  void stop() override { stop_ = true; }

 private:
  void torqueCallback(const WheelTorque::ConstPtr& msg);
  /// The state of step k; visuals at publish_rate and at the final step.
  void publishStep(std::int64_t k);
  /// The loop's state subscribers, a wheel_torque publisher and every node of wait_for are there: step 0
  /// can be answered and nobody misses the run.
  bool loopConnected() const;
  /// Subscribers of the state topics the loop uses: ground_truth, and odom when the feedback is odom.
  unsigned stateSubscribers() const;
  /// "N publisher(s) on <wheel_torque topic>", asking whether torque_controller runs when N is 0: what
  /// the stall and give-up reports say about the missing input.
  std::string torqueSources() const;
  void report(const core::LockstepProtocol::Supervision& s) const;
  std::string giveUpReason(const core::LockstepProtocol::Supervision& s) const;
  void reportFinished();

  SimulatedPlant& plant_;
  Config cfg_;
  std::atomic<bool> stop_{false};
  DeferringInlineQueue queue_;  // its mutex guards plant_ and protocol_
  core::LockstepProtocol protocol_;
  ReadyRoster roster_;
  ros::Subscriber torque_sub_;  // last: unsubscribed before the members its callback uses go
};

}  // namespace sowing_robot
