#include "sowing_robot/ros/kinematic_controller.h"

#include "sowing_robot/core/runner.h"
#include "sowing_robot/ros/component_params.h"
#include "sowing_robot/ros/msg_checks.h"

namespace sowing_robot {

KinematicController::KinematicController(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  const core::KanayamaGains gains = loadKanayama(p);
  requireValid(p, gains.validate());
  kanayama_.setGains(gains);
  ROS_INFO("kinematic_controller: kx %.4g, ky %.4g, ktheta %.4g", gains.kx, gains.ky, gains.ktheta);
  desired_pub_ = nh.advertise<DesiredVelocity>("desired_velocity", kLockstepQueue);
  error_pub_ = nh.advertise<TrackingError>("tracking_error", kLockstepQueue);
  const auto hints = ros::TransportHints().tcpNoDelay();
  odom_sub_ = nh.subscribe("odom", 50, &KinematicController::odomCallback, this, hints);
  ref_sub_ = nh.subscribe("reference", 50, &KinematicController::referenceCallback, this, hints);
}

void KinematicController::odomCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  if (!odomIsFinite(*msg)) {
    ROS_WARN_THROTTLE(1.0, "kinematic_controller: rejected non-finite odom (%ld so far)", ++rejected_);
    return;
  }
  if (inputs_.isRepeat(msg->header.stamp)) {  // the plant asked again: answer with the same numbers
    desired_pub_.publish(desired_);
    return;
  }
  if (inputs_.setFirst(*msg)) compute();
}

void KinematicController::referenceCallback(const ReferenceState::ConstPtr& msg) {
  if (!core::allFinite(msg->x, msg->y, msg->theta, msg->v, msg->omega, msg->v_dot, msg->omega_dot)) {
    ROS_WARN_THROTTLE(1.0, "kinematic_controller: rejected non-finite reference (%ld so far)", ++rejected_);
    return;
  }
  if (inputs_.setSecond(*msg)) compute();
}

void KinematicController::compute() {
  const nav_msgs::Odometry& odom = inputs_.first();
  const ReferenceState& r = inputs_.second();
  const core::Pose2D pose = poseOf(odom);
  core::Reference ref;
  ref.pose = {r.x, r.y, r.theta};
  ref.v = r.v;
  ref.omega = r.omega;
  ref.v_dot = r.v_dot;
  ref.omega_dot = r.omega_dot;
  const core::VelocityCommand cmd =
      kanayama_.compute(ref, pose, odom.twist.twist.linear.x, odom.twist.twist.angular.z);
  desired_.header.stamp = odom.header.stamp;
  desired_.v = cmd.v;
  desired_.omega = cmd.omega;
  desired_.v_dot = cmd.v_dot;
  desired_.omega_dot = cmd.omega_dot;
  desired_pub_.publish(desired_);

  const core::PostureError pe = core::Kanayama::postureError(ref.pose, pose);
  error_.header.stamp = odom.header.stamp;
  core::worldErrors(ref, pose, error_.x, error_.y, error_.theta);
  error_.xe = pe.xe;
  error_.ye = pe.ye;
  error_.thetae = pe.thetae;
  error_pub_.publish(error_);
}

}  // namespace sowing_robot
