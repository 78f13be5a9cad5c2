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
#include <string>

#include "sowing_robot/WheelTorque.h"
#include "sowing_robot/core/plant.h"
#include "sowing_robot/core/types.h"
#include "sowing_robot/ros/inline_callback_queue.h"
#include "sowing_robot/ros/path_buffer.h"

namespace sowing_robot {

class PlantSim {
 public:
  /// Loads and validates all parameters; refuses to start (exit 1) on a bad one.
  PlantSim(ros::NodeHandle nh, ros::NodeHandle pnh);
  /// Unsubscribes first: the lockstep torque callback runs on roscpp's (or a manager's) thread and uses
  /// members declared after the subscriber, which would otherwise go before it.
  ~PlantSim();
  /// Runs the simulation until shutdown, stop(), or the end of a lockstep scenario.
  /// Realtime: this thread paces the steps and serves the wheel_torque queue itself.
  /// Lockstep: the wheel_torque callback runs inline where the torque is received (roscpp's network
  /// thread, or in a nodelet manager the thread that published it) and steps the plant and publishes the
  /// next state there, with no hand-over between threads; this thread only supervises (republishes a
  /// state nobody answered, reports a stall, gives up, reports the end).
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
  /// The state at `stamp`; tf, joint_states and the path too with `visuals`; /clock at clock_rate, with
  /// visuals, or when `clock` is set.
  void publishState(const ros::Time& stamp, bool visuals, bool clock = false);
  /// False when the state is non-finite or faster than max_speed.
  bool healthy() const;
  /// Ends the process with a FATAL line (exit 2): the state diverged.
  [[noreturn]] void exitDiverged();
  /// "N publisher(s) on <wheel_torque topic>", asking whether torque_controller runs when N is 0: what
  /// the stall and give-up reports say about the missing input.
  std::string torqueSources() const;
  /// Lockstep: exit 3 with a FATAL line naming what is missing (for the state stamped `stamp`) once it
  /// has been waited for since `since` longer than lockstep_give_up (a headless run with a dead
  /// controller must end).
  void giveUpAfter(const ros::WallTime& since, const ros::Time& stamp, const char* what);
  bool running() const { return ros::ok() && !stop_; }
  void runLockstep();
  void runRealtime();
  /// Lockstep, under the queue mutex: the torque for the awaited stamp has come.
  void advanceLockstep();
  /// Lockstep: publish the state of step k (visuals at publish_rate and at the last step).
  void publishLockstepState(std::int64_t k);

  ros::NodeHandle nh_;
  Config cfg_;
  std::unique_ptr<core::Plant> plant_;
  core::Pose2D start_;

  ros::Publisher clock_pub_, odom_pub_, joint_pub_, path_pub_;
  // Before torque_sub_, which must be destroyed (unsubscribed) first: realtime uses torque_queue_,
  // lockstep inline_queue_ (whose mutex guards the plant and every member below in that mode).
  ros::CallbackQueue torque_queue_;
  InlineCallbackQueue inline_queue_;
  ros::Subscriber torque_sub_;
  tf2_ros::TransformBroadcaster tf_;
  nav_msgs::Odometry odom_msg_;
  sensor_msgs::JointState joint_msg_;
  PathBuffer path_{"odom", 0.05, 10};  // a point every 5 cm, re-sent every 10th point
  std::int64_t visual_every_ = 20;  // publish visuals every n steps
  std::int64_t clock_every_ = 1;    // publish /clock every n steps
  std::int64_t step_ = -1;          // index of the state being published (-1: none yet)

  // Realtime: served only by run()'s thread. Lockstep: guarded by inline_queue_.mutex().
  core::WheelTorques torque_;       // last accepted torque
  ros::Time torque_stamp_;          // its stamp
  bool torque_valid_ = false;
  ros::Time waiting_for_;           // lockstep: the stamp we need a torque for
  bool got_torque_ = false;
  std::int64_t last_step_ = -1;     // lockstep: index of the final state (-1: run forever)
  std::atomic<std::int64_t> progress_{0};  // lockstep: steps taken, read by the supervising thread
  std::atomic<bool> finished_{false};      // lockstep: the torque for the final state has come
  std::atomic<bool> diverged_{false};      // lockstep: the state went bad; run() ends the process
  ros::WallTime wall_start_;         // lockstep: when step 0 was published
  std::atomic<bool> stop_{false};
  std::int64_t rejected_ = 0, late_ = 0;
};

}  // namespace sowing_robot
