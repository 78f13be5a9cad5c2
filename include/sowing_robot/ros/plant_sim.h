// plant_sim: the DDMR plant as a node. Owns simulated time (/clock) and publishes odom, tf,
// joint_states and the travelled path; consumes wheel torques.
//
// Modes: realtime (paced to the wall clock, zero-order hold of the latest torque, torque timeout ->
// zero torque) and lockstep (publish the state at t_k, advance only when the torque stamped t_k has
// arrived; a late or missing torque is reported, never skipped).
#pragma once

#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/transform_broadcaster.h>

#include <atomic>
#include <memory>

#include "sowing_robot/WheelTorque.h"
#include "sowing_robot/core/plant.h"
#include "sowing_robot/core/types.h"
#include "sowing_robot/ros/path_buffer.h"

namespace sowing_robot {

class PlantSim {
 public:
  /// Loads and validates all parameters; refuses to start (exit 1) on a bad one.
  PlantSim(ros::NodeHandle nh, ros::NodeHandle pnh);
  /// Runs the simulation on the calling thread until shutdown, stop(), or the end of a lockstep
  /// scenario. The wheel_torque callback runs on this thread too (its own callback queue, served by
  /// the loop): in lockstep the torque wakes the loop directly, with no hand-over between threads.
  void run();
  /// Ask run() to return (nodelet unload); safe from any thread.
  void stop();
  /// exit_at_end: the process should end when run() returns after a lockstep scenario.
  bool exitAtEnd() const { return cfg_.lockstep && cfg_.exit_at_end; }

 private:
  struct Config {
    bool lockstep = false;
    std::int64_t period_ns = 1000000;
    double duration = 25.0;          // [s] sim; <= 0 runs forever
    double realtime_factor = 1.0;    // sim seconds per wall second in realtime mode
    double torque_timeout = 0.1;     // [s] sim, realtime mode: older torques are replaced by zero
    double publish_rate = 50.0;      // [Hz] sim, tf / joint_states / path
    double clock_rate = 0.0;         // [Hz] sim, /clock; 0 = every step
    double lockstep_retry = 0.5;     // [s] wall: republish the state if no torque came
    double lockstep_timeout = 5.0;   // [s] wall: report the missing input
    double lockstep_give_up = 120.0; // [s] wall: exit 3 when an input stays missing this long; 0 = wait forever
    int min_subscribers = 3;         // odom subscribers to wait for before step 0 (lockstep)
    double startup_delay = 0.5;      // [s] wall, lockstep: let every connection settle before step 0
    double max_speed = 20.0;         // [m/s]; beyond it (or NaN) the run is stopped as diverged
    bool exit_at_end = false;        // lockstep: exit when the scenario ends
  };

  void torqueCallback(const WheelTorque::ConstPtr& msg);
  void publishState(const ros::Time& stamp, bool visuals);
  /// Stops the process (exit 2, FATAL line) when the state is non-finite or faster than max_speed.
  void requireHealthy();
  /// Lockstep: exit 3 with a FATAL line naming what is missing once it has been waited for since
  /// `since` longer than lockstep_give_up (a headless run with a dead controller must end).
  void giveUpAfter(const ros::WallTime& since, const char* what);
  bool running() const { return ros::ok() && !stop_; }
  void runLockstep();
  void runRealtime();

  ros::NodeHandle nh_;
  Config cfg_;
  std::unique_ptr<core::Plant> plant_;
  core::Pose2D start_;

  ros::Publisher clock_pub_, odom_pub_, joint_pub_, path_pub_;
  ros::CallbackQueue torque_queue_;  // before torque_sub_, which must be destroyed (unsubscribed) first
  ros::Subscriber torque_sub_;
  tf2_ros::TransformBroadcaster tf_;
  nav_msgs::Odometry odom_msg_;
  sensor_msgs::JointState joint_msg_;
  PathBuffer path_{"odom", 0.05, 10};  // a point every 5 cm, re-sent every 10th point
  std::int64_t visual_every_ = 20;  // publish visuals every n steps
  std::int64_t clock_every_ = 1;    // publish /clock every n steps
  std::int64_t step_ = 0;           // index of the state being published

  // Served only by run()'s thread, so the torque state below needs no lock.
  core::WheelTorques torque_;       // last accepted torque
  ros::Time torque_stamp_;          // its stamp
  bool torque_valid_ = false;
  ros::Time waiting_for_;           // lockstep: the stamp we need a torque for
  bool got_torque_ = false;
  std::atomic<bool> stop_{false};
  std::int64_t rejected_ = 0, late_ = 0;
};

}  // namespace sowing_robot
