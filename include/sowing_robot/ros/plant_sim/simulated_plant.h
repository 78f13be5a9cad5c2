// The part of plant_sim that both drivers share: the simulated DDMR (a PlantModel: today's core::Plant, or
// the traction plant, plant_model.h / plant_traction.h) with its health check, the messages that show its
// state (ground_truth, /clock, tf, joint_states, the travelled path) and what its sensors read of it (odom,
// imu, fix: plant_sensors.h). Which step
// comes when, and with which torque, is the drivers' business (plant_sim_realtime.h, plant_sim_lockstep.h).
//
// The drive motors (motor/..., core/model/motor.h) sit in the model between the commanded torques and the
// wheels. What they applied goes out beside the command: `applied_torque` (sowing_robot/WheelTorque, every
// step, stamped with the command's stamp: the torque of the step from that state on; with the motors off,
// the command itself) and joint_states' effort (at publish_rate: the torque of the step that led to the state).
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/transform_broadcaster.h>

#include <cstdint>
#include <memory>
#include <string>

#include "sowing_robot/WheelTorque.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/model/robot_params.h"
#include "sowing_robot/core/model/sensors.h"
#include "sowing_robot/ros/common/path_buffer.h"
#include "sowing_robot/ros/plant_sim/contacts.h"
#include "sowing_robot/ros/plant_sim/plant_model.h"
#include "sowing_robot/ros/plant_sim/sensors.h"

namespace sowing_robot {

class SimulatedPlant {
 public:
  struct Rates {
    std::int64_t period_ns = 1000000;                           // control period: state k is stamped k * period_ns
    double publish_rate = 50.0;                                 // [Hz] sim, tf / joint_states / path
    double clock_rate = 0.0;                                    // [Hz] sim, /clock; 0 = every step
    double max_speed = 20.0;                                    // [m/s]; beyond it (or NaN) the state has diverged
    std::string odom_frame = "odom", base_frame = "base_link";  // run/odom_frame, run/base_frame (REP-105)
  };

  /// Starts the plant at rest at `start` and advertises its topics on `nh`. `model` (started at rest at
  /// `start` by the caller, see restAt()) replaces today's no-slip core::Plant when given.
  SimulatedPlant(ros::NodeHandle nh, const core::RobotParams& robot, const core::PlantDisturbance& disturbance,
                 const core::Pose2D& start, const Rates& rates, const core::Footprint& footprint,
                 std::unique_ptr<PlantModel> model = nullptr, const core::SensorParams& sensors = core::SensorParams());
  /// The state at rest at `start`.
  static core::State restAt(const core::Pose2D& start);
  /// Prints the contact report if the run did not (a realtime run, or one stopped early).
  ~SimulatedPlant();
  /// The contact report (contacts of the body, minimum clearance) as one log line, once; the model's and
  /// the motors' lines after it.
  void reportContacts();
  /// The drive motors between the commands and the wheels (before the first step). Throws
  /// std::invalid_argument when the parameters do not validate.
  void setMotor(const core::MotorParams& motor);

  /// One control period with `torque` (the command answering the state stamped `stamp`); publishes what the
  /// motors applied on applied_torque, stamped `stamp`. False when the state is then non-finite or faster than
  /// max_speed (it must not be published: divergence() says what went wrong).
  bool step(const core::WheelTorques& torque, const ros::Time& stamp);
  /// The hitch control's command (WheelTorque/tool_raised) for the steps from now on.
  void setToolRaised(bool raised) { model_->setToolRaised(raised); }
  /// The depth control's depth (WheelTorque/tool_depth; 0: the drill's nominal) for the steps from now on.
  void setToolDepth(double depth) { model_->setToolDepth(depth); }
  /// The state as step k (stamped stampOf(k)): ground_truth and the sensors' odom, imu and due fixes; tf
  /// (odom -> base_link from the encoders' odom), joint_states and the true path too with `visuals`;
  /// /clock every clock_rate, with visuals, or when `clock` is set.
  void publish(std::int64_t k, bool visuals, bool clock = false);
  /// Step k is one of the publish_rate steps that carry the visuals.
  bool visualStep(std::int64_t k) const { return k % visual_every_ == 0; }

  ros::Time stampOf(std::int64_t k) const;
  std::int64_t periodNs() const { return rates_.period_ns; }
  double dt() const { return core::secondsFromNanos(rates_.period_ns); }
  unsigned truthSubscribers() const { return truth_pub_.getNumSubscribers(); }
  unsigned odomSubscribers() const { return sensors_->odomSubscribers(); }
  /// Lockstep: the model has every input a step needs (the traction model with a draft: the plan).
  bool inputsReady() const { return model_->ready(); }
  const PlantModel& model() const { return *model_; }
  /// The FATAL text of a diverged state: its time and values, and max_speed.
  std::string divergence() const;

 private:
  bool healthy() const;
  /// "motors: ..." for the end-of-run report ("" with the motors off).
  std::string motorReport() const;

  Rates rates_;
  std::unique_ptr<PlantModel> model_;
  std::int64_t visual_every_ = 20;  // publish visuals every n steps
  std::int64_t clock_every_ = 1;    // publish /clock every n steps
  ros::Publisher clock_pub_, truth_pub_, joint_pub_, path_pub_, applied_pub_;
  std::unique_ptr<PlantSensors> sensors_;    // encoders, gyro, fix: read every step()
  std::unique_ptr<PlantContacts> contacts_;  // the body against the plan's obstacles, every step
  bool contacts_reported_ = false;
  tf2_ros::TransformBroadcaster tf_;
  nav_msgs::Odometry truth_msg_;
  sensor_msgs::JointState joint_msg_;
  WheelTorque applied_msg_;
  bool motors_ = false;                               // motor/enabled
  std::int64_t steps_ = 0, motor_limited_steps_ = 0;  // steps, and those where a motor applied less than commanded
  PathBuffer path_{"odom", 0.05, 10};                 // a point every 5 cm, re-sent every 10th point
};

}  // namespace sowing_robot
