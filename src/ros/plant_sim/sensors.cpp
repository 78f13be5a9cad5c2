#include "sowing_robot/ros/plant_sim/sensors.h"

#include <algorithm>

#include "sowing_robot/ros/common/msg_checks.h"

namespace sowing_robot {

namespace {
constexpr double kUnknown = 1e6;  // covariance of what a planar sensor does not measure (z, roll, pitch, ...)

// odom: the encoders' dead reckoning, every step.
void initOdom(nav_msgs::Odometry& m, const SensorTopicSetup& c) {
  m.header.frame_id = c.odom_frame;
  m.child_frame_id = c.base_frame;
  // Planar odometry: z, roll and pitch unknown (large), the rest from the encoders' covariance.
  m.pose.covariance[14] = m.pose.covariance[21] = m.pose.covariance[28] = kUnknown;
  // Twist: one increment's quantisation and jitter over the velocity window.
  const double window = std::max(c.params.encoder.velocity_window, 1e-3);
  const double var_v = c.suite.encoders().incrementVariance() / (window * window);
  m.twist.covariance[0] = 0.5 * var_v;
  m.twist.covariance[35] = 2.0 * var_v / (4.0 * c.nominal.L * c.nominal.L);
  m.twist.covariance[7] = m.twist.covariance[14] = kUnknown;
  m.twist.covariance[21] = m.twist.covariance[28] = kUnknown;
}
void fillOdom(core::SensorSuite& suite, nav_msgs::Odometry& m, const ros::Time& stamp, const ros::Publisher& pub) {
  const core::Odometry2D& o = suite.odometry();
  m.header.stamp = stamp;
  m.pose.pose.position.x = o.pose.x;
  m.pose.pose.position.y = o.pose.y;
  m.pose.pose.orientation = yawQuaternion(o.pose.theta);
  const int index[3] = {0, 1, 5};  // x, y, yaw in the 6x6 row-major covariance
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m.pose.covariance[6 * index[i] + index[j]] = o.covariance(i, j);
  m.twist.twist.linear.x = o.v;
  m.twist.twist.angular.z = o.omega;
  publishShared(pub, m);
}

// imu: the gyro's yaw rate, every step.
void initImu(sensor_msgs::Imu& m, const SensorTopicSetup& c) {
  m.header.frame_id = c.base_frame;
  m.orientation.w = 1.0;
  m.orientation_covariance[0] = -1.0;  // not provided (sensor_msgs/Imu convention)
  m.linear_acceleration_covariance[0] = -1.0;
  const double var_w = c.params.imu.noise * c.params.imu.noise;
  m.angular_velocity_covariance[0] = m.angular_velocity_covariance[4] = kUnknown;
  m.angular_velocity_covariance[8] = var_w;
}
void fillImu(core::SensorSuite& suite, sensor_msgs::Imu& m, const ros::Time& stamp, const ros::Publisher& pub) {
  m.header.stamp = stamp;
  m.angular_velocity.z = suite.yawRate();
  publishShared(pub, m);
}

// fix: each fix whose latency has passed, stamped with its measurement time.
void initFix(geometry_msgs::PoseWithCovarianceStamped& m, const SensorTopicSetup& c) {
  m.header.frame_id = c.odom_frame;
  m.pose.pose.orientation.w = 1.0;
  const double var_xy = c.params.fix.sigma * c.params.fix.sigma;
  m.pose.covariance[0] = m.pose.covariance[7] = var_xy;
  m.pose.covariance[14] = m.pose.covariance[21] = kUnknown;
  m.pose.covariance[28] = m.pose.covariance[35] = kUnknown;
}
void fillFix(core::SensorSuite& suite, geometry_msgs::PoseWithCovarianceStamped& m, const ros::Time& stamp,
             const ros::Publisher& pub) {
  for (const core::FixMeasurement& f : suite.dueFixes(stamp.toSec())) {
    m.header.stamp.fromNSec(static_cast<std::uint64_t>(std::llround(f.stamp * 1e9)));
    m.pose.pose.position.x = f.xy.x();
    m.pose.pose.position.y = f.xy.y();
    publishShared(pub, m);
  }
}
}  // namespace

PlantSensors::PlantSensors(ros::NodeHandle nh, const core::SensorParams& params, const core::RobotParams& nominal,
                           const core::State& initial, const std::string& odom_frame, const std::string& base_frame)
    : params_(params), sensors_(params, nominal) {
  sensors_.start(initial);
  // Every sensor's topic, advertised and published in this order: a new sensor's message is one line here.
  const Setup setup{params, nominal, sensors_, odom_frame, base_frame};
  odom_ = add<nav_msgs::Odometry>(nh, "odom", initOdom, fillOdom, setup);
  add<sensor_msgs::Imu>(nh, "imu", initImu, fillImu, setup);
  add<geometry_msgs::PoseWithCovarianceStamped>(nh, "fix", initFix, fillFix, setup);
}

void PlantSensors::update(double t, const core::State& s, double dt) {
  time_ = t;
  sensors_.update(t, s, dt);
}

void PlantSensors::publish(const ros::Time& stamp) {
  for (const std::unique_ptr<Topic>& topic : topics_) topic->publish(sensors_, stamp);
}

geometry_msgs::TransformStamped PlantSensors::odomTransform() const {
  geometry_msgs::TransformStamped tf;
  const nav_msgs::Odometry& odom = odom_->message();
  tf.header = odom.header;
  tf.child_frame_id = odom.child_frame_id;
  tf.transform.translation.x = odom.pose.pose.position.x;
  tf.transform.translation.y = odom.pose.pose.position.y;
  tf.transform.rotation = odom.pose.pose.orientation;
  return tf;
}

}  // namespace sowing_robot
