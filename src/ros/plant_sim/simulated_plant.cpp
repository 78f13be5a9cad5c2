#include "sowing_robot/ros/plant_sim/simulated_plant.h"

#include <rosgraph_msgs/Clock.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sowing_robot/ros/common/msg_checks.h"

namespace sowing_robot {

core::State SimulatedPlant::restAt(const core::Pose2D& start) {
  core::State x0 = core::State::Zero();
  x0[core::X] = start.x;
  x0[core::Y] = start.y;
  x0[core::THETA] = start.theta;
  return x0;
}

SimulatedPlant::SimulatedPlant(ros::NodeHandle nh, const core::RobotParams& robot,
                               const core::PlantDisturbance& disturbance, const core::Pose2D& start, const Rates& rates,
                               const core::Footprint& footprint, std::unique_ptr<PlantModel> model,
                               const core::SensorParams& sensors)
    : rates_(rates),
      model_(model ? std::move(model) : std::make_unique<NoSlipModel>(robot, disturbance, restAt(start))) {
  sensors_ = std::make_unique<PlantSensors>(nh, sensors, robot, model_->state(), rates.odom_frame, rates.base_frame);
  visual_every_ = std::max<std::int64_t>(1, std::llround(1e9 / rates_.publish_rate / rates_.period_ns));
  if (rates_.clock_rate > 0.0)
    clock_every_ = std::max<std::int64_t>(1, std::llround(1e9 / rates_.clock_rate / rates_.period_ns));

  clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  truth_pub_ = nh.advertise<nav_msgs::Odometry>("ground_truth", kLockstepQueue);
  joint_pub_ = nh.advertise<sensor_msgs::JointState>("joint_states", kLockstepQueue);
  applied_pub_ = nh.advertise<WheelTorque>("applied_torque", kLockstepQueue);
  path_pub_ = nh.advertise<nav_msgs::Path>("travelled_path", 1, true);

  truth_msg_.header.frame_id = rates.odom_frame;
  truth_msg_.child_frame_id = rates.base_frame;
  path_ = PathBuffer(rates.odom_frame, 0.05, 10);
  joint_msg_.name = {"right_wheel_joint", "left_wheel_joint"};
  joint_msg_.position.resize(2);
  joint_msg_.velocity.resize(2);
  joint_msg_.effort.resize(2);
  contacts_ = std::make_unique<PlantContacts>(nh, footprint, rates.odom_frame, rates.base_frame);
}

SimulatedPlant::~SimulatedPlant() {
  if (contacts_reported_) return;
  // stdout, not rosconsole: at shutdown the logger may already be gone.
  std::printf("plant_sim: %s", contacts_->finish().c_str());  // the report ends with a newline
  const std::string model = model_->report();
  if (!model.empty()) std::printf("plant_sim: %s\n", model.c_str());
  const std::string motors = motorReport();
  if (!motors.empty()) std::printf("plant_sim: %s\n", motors.c_str());
  std::fflush(stdout);
}

void SimulatedPlant::reportContacts() {
  if (contacts_reported_) return;
  contacts_reported_ = true;
  std::string report = contacts_->finish();
  if (!report.empty() && report.back() == '\n') report.pop_back();
  ROS_INFO("plant_sim: %s", report.c_str());
  const std::string model = model_->report();
  if (!model.empty()) ROS_INFO("plant_sim: %s", model.c_str());
  const std::string motors = motorReport();
  if (!motors.empty()) ROS_INFO("plant_sim: %s", motors.c_str());
}

void SimulatedPlant::setMotor(const core::MotorParams& motor) {
  model_->setMotor(motor);
  motors_ = motor.enabled;
}

std::string SimulatedPlant::motorReport() const {
  if (!motors_) return "";
  char text[160];
  std::snprintf(text, sizeof text,
                "motors: the applied torque differed from the command (band or lag) in %lld of %lld steps",
                static_cast<long long>(motor_limited_steps_), static_cast<long long>(steps_));
  return text;
}

ros::Time SimulatedPlant::stampOf(std::int64_t k) const {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(k * rates_.period_ns));
  return t;
}

bool SimulatedPlant::step(const core::WheelTorques& torque, const ros::Time& stamp) {
  model_->step(torque.right, torque.left, dt());
  if (!healthy()) return false;
  applied_msg_.header.stamp = stamp;
  model_->appliedTorques(applied_msg_.right, applied_msg_.left);
  publishShared(applied_pub_, applied_msg_);
  ++steps_;
  if (applied_msg_.right != torque.right || applied_msg_.left != torque.left) ++motor_limited_steps_;
  const core::State& s = model_->state();
  contacts_->update(model_->time(), {s[core::X], s[core::Y], s[core::THETA]});
  // The sensors on the stamp grid (the fix's rate and latency are counted in stamps, not summed dt).
  sensors_->update(stampOf(std::llround(model_->time() * 1e9 / rates_.period_ns)).toSec(), s, dt());
  return true;
}

bool SimulatedPlant::healthy() const {
  const core::State& s = model_->state();
  return std::isfinite(s.sum()) && std::fabs(s[core::V]) <= rates_.max_speed;
}

std::string SimulatedPlant::divergence() const {
  const core::State& s = model_->state();
  char text[320];
  std::snprintf(text, sizeof text,
                "state diverged at t=%.6f s (x %g, y %g, theta %g, v %g, omega %g; max_speed %g m/s): stopping the "
                "run instead of publishing garbage",
                model_->time(), s[core::X], s[core::Y], s[core::THETA], s[core::V], s[core::OMEGA], rates_.max_speed);
  return text;
}

void SimulatedPlant::publish(std::int64_t k, bool visuals, bool clock) {
  const ros::Time stamp = stampOf(k);
  const core::State& s = model_->state();
  truth_msg_.header.stamp = stamp;
  truth_msg_.pose.pose.position.x = s[core::X];
  truth_msg_.pose.pose.position.y = s[core::Y];
  truth_msg_.pose.pose.orientation = yawQuaternion(s[core::THETA]);
  truth_msg_.twist.twist.linear.x = s[core::V];
  truth_msg_.twist.twist.angular.z = s[core::OMEGA];
  publishShared(truth_pub_, truth_msg_);
  sensors_->publish(stamp);
  // Nothing in the control loop reads /clock (every node works on header stamps); it serves ROS time
  // for logs, rosbag and rviz, so it may go out less often than every step (clock_rate), and after the
  // state, off the loop's critical path (it has a link to every node).
  if (clock || visuals || k % clock_every_ == 0) {
    rosgraph_msgs::Clock c;
    c.clock = stamp;
    clock_pub_.publish(c);
  }
  if (!visuals) return;

  tf_.sendTransform(sensors_->odomTransform());  // REP-105: odom -> base_link is what odometry believes

  joint_msg_.header.stamp = stamp;
  joint_msg_.position[0] = s[core::PHI_R];
  joint_msg_.position[1] = s[core::PHI_L];
  model_->wheelRates(joint_msg_.velocity[0], joint_msg_.velocity[1]);
  joint_msg_.effort[0] = applied_msg_.right;  // the motors' torque over the step that led here
  joint_msg_.effort[1] = applied_msg_.left;
  joint_pub_.publish(joint_msg_);
  model_->publishVisuals(stamp);

  geometry_msgs::PoseStamped pose;
  pose.header = truth_msg_.header;
  pose.pose = truth_msg_.pose.pose;
  if (path_.add(pose)) path_pub_.publish(path_.path());
}

}  // namespace sowing_robot
