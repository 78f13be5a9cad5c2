#include "sowing_robot/ros/torque_controller.h"

#include "sowing_robot/ros/component_params.h"
#include "sowing_robot/ros/msg_checks.h"

namespace sowing_robot {

TorqueController::TorqueController(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  core::RobotParams robot;
  p.allow("robot_description");  // a private URDF may override the global one
  std::string error = loadRobotParams(pnh, robot);
  const std::int64_t period = loadControlPeriod(p, error);
  const core::SlidingModeParams params = loadSlidingMode(p, error);
  requireValid(p, error.empty() ? params.validate() : error);
  dt_ = core::secondsFromNanos(period);
  smc_ = std::make_unique<core::SlidingModeController>(params, robot);
  ROS_INFO("torque_controller: %s, p/q %d/%d, beta %.4g/%.4g, K %.4g/%.4g, eta %.4g/%.4g, rates %.4g/%.4g, "
           "m0 in [%.4g, %.4g] from %.4f kg, I0 in [%.4g, %.4g] from %.5f kg m^2, switching %s (width %.4g), "
           "max torque %.4g N m, %.0f Hz",
           params.adaptive ? "ATSMC" : "TSMC", params.p, params.q, params.beta_v, params.beta_omega, params.k1,
           params.k2, params.eta1, params.eta2, params.rate_m, params.rate_i, params.m0_min, params.m0_max,
           smc_->m0Hat(), params.i0_min, params.i0_max, smc_->i0Hat(),
           core::SwitchFunction::name(params.switching.type), params.switching.width, params.max_torque, 1.0 / dt_);
  state_.mode = params.adaptive ? "atsmc" : "tsmc";
  torque_pub_ = nh.advertise<WheelTorque>("wheel_torque", kLockstepQueue);
  state_pub_ = pnh.advertise<TorqueControllerState>("state", kLockstepQueue);
  const auto hints = ros::TransportHints().tcpNoDelay();
  odom_sub_ = nh.subscribe("odom", 50, &TorqueController::odomCallback, this, hints);
  desired_sub_ = nh.subscribe("desired_velocity", 50, &TorqueController::desiredCallback, this, hints);
}

void TorqueController::odomCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  if (!odomIsFinite(*msg)) {
    ROS_WARN_THROTTLE(1.0, "torque_controller: rejected non-finite odom (%ld so far)", ++rejected_);
    return;
  }
  if (inputs_.setFirst(*msg)) compute();
}

void TorqueController::desiredCallback(const DesiredVelocity::ConstPtr& msg) {
  if (!core::allFinite(msg->v, msg->omega, msg->v_dot, msg->omega_dot)) {
    ROS_WARN_THROTTLE(1.0, "torque_controller: rejected non-finite desired velocity (%ld so far)", ++rejected_);
    return;
  }
  if (inputs_.isRepeat(msg->header.stamp)) {  // the same period again: never integrate twice
    torque_pub_.publish(torque_);
    return;
  }
  if (inputs_.setSecond(*msg)) compute();
}

void TorqueController::compute() {
  const nav_msgs::Odometry& odom = inputs_.first();
  const DesiredVelocity& d = inputs_.second();
  const core::VelocityCommand cmd{d.v, d.omega, d.v_dot, d.omega_dot};
  const core::SlidingModeOutput out =
      smc_->update(cmd, odom.twist.twist.linear.x, odom.twist.twist.angular.z, dt_);
  torque_.header.stamp = odom.header.stamp;
  torque_.right = out.torques.right;
  torque_.left = out.torques.left;
  torque_pub_.publish(torque_);
  if (out.saturated)
    ROS_WARN_THROTTLE(2.0, "torque_controller: wheel torque saturated at %.4g N m (%ld periods so far)",
                      smc_->params().max_torque, ++saturated_);

  state_.header.stamp = odom.header.stamp;
  state_.e_v = out.e_v;
  state_.e_omega = out.e_omega;
  state_.s_v = out.s_v;
  state_.s_omega = out.s_omega;
  state_.m0_hat = smc_->m0Hat();
  state_.i0_hat = smc_->i0Hat();
  state_.u1 = out.u1;
  state_.u2 = out.u2;
  state_.saturated = out.saturated;
  state_pub_.publish(state_);
}

}  // namespace sowing_robot
