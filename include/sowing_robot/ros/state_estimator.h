// state_estimator: the EKF of core/estimation/ekf.h between the sensors and the controllers (feedback:=fused).
// odom (encoder dead reckoning) + imu (yaw rate) paired by stamp -> one odometry/filtered per odom
// stamp; fix (late position fixes) applied at their measurement stamp once the estimate is
// estimator/fix/delay newer, so which fixes an estimate holds depends on stamps only (repeatable runs).
// In lockstep with fix_source set, a step waits for the fixes due by it (core/estimation/fix_await.h).
#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>

#include <deque>
#include <memory>

#include "sowing_robot/core/estimation/ekf.h"
#include "sowing_robot/core/estimation/fix_await.h"
#include "sowing_robot/ros/common/ready_roster.h"
#include "sowing_robot/ros/common/stamp_pair.h"

namespace sowing_robot {

class StateEstimator {
 public:
  /// Throws NodeFailure (badParameter) for a bad estimator/... value.
  StateEstimator(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~StateEstimator();

 private:
  struct Loaded;  // the validated parameters and the URDF's half track
  static Loaded loadParams(ros::NodeHandle nh, ros::NodeHandle pnh);
  StateEstimator(ros::NodeHandle nh, ros::NodeHandle pnh, const Loaded& loaded);
  void odomCallback(const nav_msgs::Odometry::ConstPtr& msg);
  void imuCallback(const sensor_msgs::Imu::ConstPtr& msg);
  void fixCallback(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& msg);
  /// The paired odom and imu: step now, or hold them until the fixes due by them have come.
  void paired();
  /// The held steps, oldest first, while nothing due by the oldest is awaited.
  void runHeld();
  /// One step: predict, apply the fixes due, publish.
  void step(const nav_msgs::Odometry& odom, const sensor_msgs::Imu& imu);
  void publish(const nav_msgs::Odometry& odom, const sensor_msgs::Imu& imu);

  core::Ekf ekf_;
  core::FixQueue fixes_;
  std::unique_ptr<core::FixAwait> await_;  // lockstep with fix_source: the plant's fix schedule
  struct Held {
    nav_msgs::Odometry odom;
    sensor_msgs::Imu imu;
  };
  std::deque<Held> held_;                 // paired steps waiting for a fix due by the oldest, in stamp order
  Eigen::Matrix2d increment_covariance_;  // of each step's (distance, dtheta): the encoders' quantisation
  ros::Subscriber odom_sub_, imu_sub_, fix_sub_;
  ros::Publisher filtered_pub_;
  // Both streams come from the plant at the same rate on separate connections, either may run ahead
  // (a burst from a recorder replay, a busy core in realtime): hold up to a few seconds of either.
  ListenerPair<nav_msgs::Odometry, sensor_msgs::Imu> inputs_;
  nav_msgs::Odometry last_odom_;  // the previous step's odom: the increments are taken from it
  nav_msgs::Odometry filtered_;   // the last answer (republished when the plant asks again)
  long rejected_inputs_ = 0, late_fixes_ = 0, lost_fixes_ = 0;
  core::FixCounts reported_;  // counts already warned about
  ReadyAnnouncer ready_;      // plant_sim waits for it before step 0
};

}  // namespace sowing_robot
