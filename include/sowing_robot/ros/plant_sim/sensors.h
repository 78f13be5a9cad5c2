// plant_sim's sensors: the core's sensor suite (core/simulation/sensor_feeds.h: the seeded sensors of
// core/model/sensors.h, read on the plant's true state exactly as the in-process loop reads them), and their
// messages. Topics (relative, docs/sensors.md):
//   odom  nav_msgs/Odometry                    encoder dead reckoning (nominal R, L), every step; its
//                                              pose covariance grows; odom -> base_link tf from it
//   imu   sensor_msgs/Imu                      yaw rate (omega + bias + noise), every step
//   fix   geometry_msgs/PoseWithCovarianceStamped  the axle midpoint + noise at sensors/fix/rate,
//                                              stamped with its measurement time, sent latency later
// The true state goes out on ground_truth (SimulatedPlant). update() reads the sensors once per plant
// step; publish() sends what they read, and may be called again for the same step (a lockstep re-send:
// the same odom and imu again, no fix twice).
#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>

#include <string>

#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/model/robot_params.h"
#include "sowing_robot/core/model/sensors.h"
#include "sowing_robot/core/simulation/sensor_feeds.h"

namespace sowing_robot {

class PlantSensors {
 public:
  /// Starts every sensor at `initial` (time 0) and advertises odom, imu and fix on nh. `nominal`: the
  /// robot the encoders' dead reckoning assumes (the URDF's R and L). Throws std::invalid_argument for
  /// invalid parameters (the node validated them before).
  PlantSensors(ros::NodeHandle nh, const core::SensorParams& params, const core::RobotParams& nominal,
               const core::State& initial, const std::string& odom_frame, const std::string& base_frame);

  /// Reads every sensor at the true state `s` at time t, dt after the previous reading.
  void update(double t, const core::State& s, double dt);
  /// odom and imu of the last reading and the fixes whose latency has passed, stamped `stamp` (the fix
  /// with its measurement time).
  void publish(const ros::Time& stamp);
  /// The odom -> base_link transform of the last odom published.
  geometry_msgs::TransformStamped odomTransform() const;
  unsigned odomSubscribers() const { return odom_pub_.getNumSubscribers(); }

 private:
  core::SensorParams params_;
  core::SensorSuite sensors_;
  double time_ = 0.0;
  ros::Publisher odom_pub_, imu_pub_, fix_pub_;
  nav_msgs::Odometry odom_msg_;
  sensor_msgs::Imu imu_msg_;
  geometry_msgs::PoseWithCovarianceStamped fix_msg_;
};

}  // namespace sowing_robot
