// What drives plant_sim's steps: the realtime driver (the wall clock paces them) or the lockstep driver
// (each torque for the awaited state releases the next one). PlantSim owns one of them.
#pragma once

#include <ros/ros.h>

#include <functional>

#include "sowing_robot/WheelTorque.h"

namespace sowing_robot {

class PlantSimDriver {
 public:
  virtual ~PlantSimDriver() = default;
  /// Runs until shutdown, stop(), or the end of the scenario. Throws NodeFailure (node_failure.h) when
  /// the run cannot go on: kDiverged, or kGaveUp (lockstep). Nothing is stepped after that.
  virtual void run() = 0;
  /// Ask run() to return; safe from any thread.
  virtual void stop() = 0;
};

/// The wheel_torque subscription of a driver, with its callbacks on `queue` (TCP_NODELAY, as every
/// lockstep topic).
inline ros::Subscriber subscribeTorque(ros::NodeHandle nh, ros::CallbackQueueInterface* queue,
                                       std::function<void(const WheelTorque::ConstPtr&)> callback) {
  ros::SubscribeOptions options =
      ros::SubscribeOptions::create<WheelTorque>("wheel_torque", 50, std::move(callback), ros::VoidPtr(), queue);
  options.transport_hints = ros::TransportHints().tcpNoDelay();
  return nh.subscribe(options);
}

}  // namespace sowing_robot
