#include "sowing_robot/ros/plant_sim/sensors.h"

#include <algorithm>

#include "sowing_robot/ros/common/msg_checks.h"

namespace sowing_robot {

namespace {
constexpr double kUnknown = 1e6;  // covariance of what a planar sensor does not measure (z, roll, pitch, ...)
}  // namespace

PlantSensors::PlantSensors(ros::NodeHandle nh, const core::SensorParams& params, const core::RobotParams& nominal,
                           const core::State& initial, const std::string& odom_frame, const std::string& base_frame)
    : params_(params), sensors_(params, nominal) {
  sensors_.start(initial);

  odom_pub_ = nh.advertise<nav_msgs::Odometry>("odom", kLockstepQueue);
  imu_pub_ = nh.advertise<sensor_msgs::Imu>("imu", kLockstepQueue);
  fix_pub_ = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("fix", kLockstepQueue);

  odom_msg_.header.frame_id = odom_frame;
  odom_msg_.child_frame_id = base_frame;
  // Planar odometry: z, roll and pitch unknown (large), the rest from the encoders' covariance.
  odom_msg_.pose.covariance[14] = odom_msg_.pose.covariance[21] = odom_msg_.pose.covariance[28] = kUnknown;
  // Twist: one increment's quantisation and jitter over the velocity window.
  const double window = std::max(params.encoder.velocity_window, 1e-3);
  const double var_v = sensors_.encoders().incrementVariance() / (window * window);
  odom_msg_.twist.covariance[0] = 0.5 * var_v;
  odom_msg_.twist.covariance[35] = 2.0 * var_v / (4.0 * nominal.L * nominal.L);
  odom_msg_.twist.covariance[7] = odom_msg_.twist.covariance[14] = kUnknown;
  odom_msg_.twist.covariance[21] = odom_msg_.twist.covariance[28] = kUnknown;

  imu_msg_.header.frame_id = base_frame;
  imu_msg_.orientation.w = 1.0;
  imu_msg_.orientation_covariance[0] = -1.0;  // not provided (sensor_msgs/Imu convention)
  imu_msg_.linear_acceleration_covariance[0] = -1.0;
  const double var_w = params.imu.noise * params.imu.noise;
  imu_msg_.angular_velocity_covariance[0] = imu_msg_.angular_velocity_covariance[4] = kUnknown;
  imu_msg_.angular_velocity_covariance[8] = var_w;

  fix_msg_.header.frame_id = odom_frame;
  fix_msg_.pose.pose.orientation.w = 1.0;
  const double var_xy = params.fix.sigma * params.fix.sigma;
  fix_msg_.pose.covariance[0] = fix_msg_.pose.covariance[7] = var_xy;
  fix_msg_.pose.covariance[14] = fix_msg_.pose.covariance[21] = kUnknown;
  fix_msg_.pose.covariance[28] = fix_msg_.pose.covariance[35] = kUnknown;
}

void PlantSensors::update(double t, const core::State& s, double dt) {
  time_ = t;
  sensors_.update(t, s, dt);
}

void PlantSensors::publish(const ros::Time& stamp) {
  const core::Odometry2D& o = sensors_.odometry();
  odom_msg_.header.stamp = stamp;
  odom_msg_.pose.pose.position.x = o.pose.x;
  odom_msg_.pose.pose.position.y = o.pose.y;
  odom_msg_.pose.pose.orientation = yawQuaternion(o.pose.theta);
  const int index[3] = {0, 1, 5};  // x, y, yaw in the 6x6 row-major covariance
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) odom_msg_.pose.covariance[6 * index[i] + index[j]] = o.covariance(i, j);
  odom_msg_.twist.twist.linear.x = o.v;
  odom_msg_.twist.twist.angular.z = o.omega;
  publishShared(odom_pub_, odom_msg_);

  imu_msg_.header.stamp = stamp;
  imu_msg_.angular_velocity.z = sensors_.yawRate();
  publishShared(imu_pub_, imu_msg_);

  for (const core::FixMeasurement& m : sensors_.dueFixes(stamp.toSec())) {
    fix_msg_.header.stamp.fromNSec(static_cast<std::uint64_t>(std::llround(m.stamp * 1e9)));
    fix_msg_.pose.pose.position.x = m.xy.x();
    fix_msg_.pose.pose.position.y = m.xy.y();
    publishShared(fix_pub_, fix_msg_);
  }
}

geometry_msgs::TransformStamped PlantSensors::odomTransform() const {
  geometry_msgs::TransformStamped tf;
  tf.header = odom_msg_.header;
  tf.child_frame_id = odom_msg_.child_frame_id;
  tf.transform.translation.x = odom_msg_.pose.pose.position.x;
  tf.transform.translation.y = odom_msg_.pose.pose.position.y;
  tf.transform.rotation = odom_msg_.pose.pose.orientation;
  return tf;
}

}  // namespace sowing_robot
