// plant_sim: the DDMR plant as a node. Owns simulated time (/clock) and publishes odom, tf,
// joint_states and the travelled path; consumes wheel torques.
//
// Modes: realtime (paced to the wall clock, zero-order hold of the latest torque, torque timeout ->
// zero torque; plant_sim/realtime.h) and lockstep (publish the state at t_k, advance only when the
// torque stamped t_k has arrived; a late or missing torque is reported, never skipped;
// plant_sim/lockstep.h, its protocol in core/simulation/lockstep.h). Both step and publish through one
// SimulatedPlant (plant_sim/simulated_plant.h).
#pragma once

#include <ros/ros.h>

#include <cstdint>
#include <memory>

#include "sowing_robot/ros/common/node_failure.h"
#include "sowing_robot/ros/plant_sim/driver.h"
#include "sowing_robot/ros/plant_sim/simulated_plant.h"

namespace sowing_robot {

class PlantSim {
 public:
  /// Loads and validates all parameters; refuses to start (exit 1) on a bad one.
  PlantSim(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~PlantSim();
  /// Runs the simulation until shutdown, stop(), or the end of a lockstep scenario.
  /// Realtime: this thread paces the steps and serves the wheel_torque queue itself.
  /// Lockstep: the wheel_torque callback runs inline where the torque is received (roscpp's network
  /// thread, or in a nodelet manager the thread that published it) and steps the plant and publishes the
  /// next state there, with no hand-over between threads; this thread only supervises (republishes a
  /// state nobody answered, reports a stall, gives up, reports the end).
  /// Throws NodeFailure when the run cannot go on: kDiverged (the state went bad) or kGaveUp (lockstep:
  /// an input stayed missing longer than lockstep_give_up). Nothing is stepped or published after it; the
  /// caller logs it (one FATAL line) and decides: a node's main exits with its code, a nodelet stops.
  void run();
  /// Ask run() to return (nodelet unload); safe from any thread.
  void stop();
  /// exit_at_end: the process should end when run() returns after a lockstep scenario.
  bool exitAtEnd() const { return cfg_.lockstep && cfg_.exit_at_end; }

 private:
  struct Config {
    bool lockstep = false;
    std::int64_t period_ns = 1000000;
    double duration = 25.0;             // [s] sim; <= 0 runs forever
    double realtime_factor = 1.0;       // sim seconds per wall second in realtime mode
    double torque_timeout = 0.1;        // [s] sim, realtime mode: older torques are replaced by zero
    double publish_rate = 50.0;         // [Hz] sim, tf / joint_states / path
    double clock_rate = 0.0;            // [Hz] sim, /clock; 0 = every step
    double lockstep_retry = 0.5;        // [s] wall: republish the state if no torque came
    double lockstep_timeout = 5.0;      // [s] wall: report the missing input
    double lockstep_give_up = 120.0;    // [s] wall: exit 3 when an input stays missing this long; 0 = wait forever
    int min_subscribers = 3;            // state subscribers to wait for before step 0 (lockstep)
    std::vector<std::string> wait_for;  // nodes that must have announced on `ready` before step 0 (lockstep)
    bool loop_on_odom = false;          // the controllers' feedback is odom: its subscribers count too
    double startup_delay = 0.5;         // [s] wall, lockstep: let every connection settle before step 0
    double max_speed = 20.0;            // [m/s]; beyond it (or NaN) the run is stopped as diverged
    bool exit_at_end = false;           // lockstep: exit when the scenario ends
  };

  Config cfg_;
  std::unique_ptr<SimulatedPlant> plant_;
  std::unique_ptr<PlantSimDriver> driver_;  // after plant_: goes first, its torque subscription with it
};

}  // namespace sowing_robot
