// plant_sim's realtime driver: the wall clock paces the steps (realtime_factor); each step uses the
// newest torque received, or zero torque once it is older than torque_timeout (simulated time).
#pragma once

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <atomic>

#include "sowing_robot/WheelTorque.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/ros/plant_sim/driver.h"
#include "sowing_robot/ros/plant_sim/simulated_plant.h"

namespace sowing_robot {

class RealtimeDriver : public PlantSimDriver {
 public:
  struct Config {
    double realtime_factor = 1.0;  // sim seconds per wall second
    double torque_timeout = 0.1;   // [s] sim: older torques are replaced by zero
  };
  RealtimeDriver(ros::NodeHandle nh, SimulatedPlant& plant, const Config& config);
  /// Unsubscribes before the queue goes.
  ~RealtimeDriver() override;
  /// Paces the steps and serves the wheel_torque queue on the calling thread. Throws NodeFailure
  /// (kDiverged) when the state goes bad.
  void run() override;
  void stop() override;

 private:
  void torqueCallback(const WheelTorque::ConstPtr& msg);

  SimulatedPlant& plant_;
  Config cfg_;
  std::atomic<bool> stop_{false};
  ros::CallbackQueue queue_;  // served by run()'s thread only: the members below need no lock
  ros::Subscriber torque_sub_;
  core::WheelTorques torque_;  // last accepted torque
  ros::Time torque_stamp_;     // its stamp
  bool torque_valid_ = false;
  bool tool_raised_ = false;  // its hitch command (WheelTorque/tool_raised)
  double tool_depth_ = 0.0;   // its depth control's depth (WheelTorque/tool_depth; 0: nominal)
  long rejected_ = 0;
};

}  // namespace sowing_robot
