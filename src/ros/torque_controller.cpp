#include "sowing_robot/ros/torque_controller.h"

#include "sowing_robot/ros/component_params.h"
#include "sowing_robot/core/validation.h"
#include "sowing_robot/ros/msg_checks.h"
#include "sowing_robot/ros/run_settings.h"

namespace sowing_robot {

TorqueController::TorqueController(ros::NodeHandle nh, ros::NodeHandle pnh) : lockstep_(lockstepRun(nh)) {
  ParamReader p(pnh);
  core::RobotParams robot;
  p.allow("robot_description");  // a private URDF may override the global one
  std::string error = loadRobotParams(pnh, robot);
  const std::int64_t period = loadControlPeriod(p, error);
  const core::SlidingModeParams params = loadSlidingMode(p, error);
  input_timeout_ = p.get("input_timeout", input_timeout_);
  if (error.empty()) error = core::firstError({params.validate(), core::checkPositive("input_timeout", input_timeout_, "s")});
  requireValid(p, error);
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
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<TorqueControllerConfig>>(pnh);
  reconfigure_->setCallback([this](TorqueControllerConfig& c, uint32_t level) { reconfigure(c, level); });
  torque_pub_ = nh.advertise<WheelTorque>("wheel_torque", kLockstepQueue);
  state_pub_ = pnh.advertise<TorqueControllerState>("state", kLockstepQueue);
  const auto hints = ros::TransportHints().tcpNoDelay();
  odom_sub_ = nh.subscribe("odom", kLockstepQueue, &TorqueController::odomCallback, this, hints);
  desired_sub_ = nh.subscribe("desired_velocity", kLockstepQueue, &TorqueController::desiredCallback, this, hints);
}

namespace {
/// The live-tunable subset of SlidingModeParams and its dynamic_reconfigure fields, listed once:
/// `each(param, config_field)` is called for every pair (P and C may be const, for the direction read).
template <typename P, typename C, typename F>
void forEachTunable(P& p, C& c, F each) {
  each(p.beta_v, c.beta_v);
  each(p.beta_omega, c.beta_omega);
  each(p.k1, c.k1);
  each(p.k2, c.k2);
  each(p.eta1, c.eta1);
  each(p.eta2, c.eta2);
  each(p.rate_m, c.rate_m);
  each(p.rate_i, c.rate_i);
  each(p.max_torque, c.max_torque);
  each(p.switching.width, c.switch_width);
}
void toParams(const TorqueControllerConfig& c, core::SlidingModeParams& p) {
  forEachTunable(p, c, [](double& param, const double& field) { param = field; });
}
void toConfig(const core::SlidingModeParams& p, TorqueControllerConfig& c) {
  forEachTunable(p, c, [](const double& param, double& field) { field = param; });
  c.switching = core::SwitchFunction::name(p.switching.type);
}
}  // namespace

void TorqueController::reconfigure(TorqueControllerConfig& config, uint32_t) {
  // The server's first call repeats the start-up values; applying them again changes nothing.
  const core::SlidingModeParams old = smc_->params();
  core::SlidingModeParams p = old;
  toParams(config, p);
  std::string error;
  if (!core::SwitchFunction::parse(config.switching, p.switching.type))
    error = "switching = '" + config.switching + "' must be one of sign, sat, relay, atan, tanh";
  if (error.empty()) error = p.validate();
  if (!error.empty()) {
    ROS_WARN("torque_controller: rejected gain change: %s; keeping the previous gains", error.c_str());
    toConfig(old, config);  // the server then reports (and stores) the values really in force
    return;
  }
  smc_->setParams(p);
  ROS_INFO("torque_controller: gains now beta %g/%g, K %g/%g, eta %g/%g, rates %g/%g, max torque %g, %s (%g)",
           p.beta_v, p.beta_omega, p.k1, p.k2, p.eta1, p.eta2, p.rate_m, p.rate_i, p.max_torque,
           core::SwitchFunction::name(p.switching.type), p.switching.width);
}

void TorqueController::odomCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  if (!odomIsFinite(*msg)) {
    ROS_WARN_THROTTLE(1.0, "torque_controller: rejected non-finite odom (%ld so far)", ++rejected_);
    return;
  }
  if (inputs_.setFirst(*msg)) {
    compute();
  } else {
    holdZeroIfStale(*msg);
  }
}

bool TorqueController::holdZeroIfStale(const nav_msgs::Odometry& odom) {
  // Lockstep: the desired velocity for this stamp is on its way (a restarted kinematic controller answers
  // the re-sent state), and simulated time stands still until it comes: wait for it.
  if (lockstep_) return false;
  const bool have = inputs_.any();
  const double age = have ? (odom.header.stamp - inputs_.lastStamp()).toSec() : odom.header.stamp.toSec();
  if (age <= input_timeout_) return false;
  // The kinematic controller is silent (dead or restarting): command zero torque, the robot coasts.
  ROS_WARN_THROTTLE(1.0, "torque_controller: no desired_velocity for %.3f s (input_timeout %.3f s): zero torque",
                    age, input_timeout_);
  stale_ = true;
  torque_.header.stamp = odom.header.stamp;
  torque_.right = torque_.left = 0.0;
  publishShared(torque_pub_, torque_);
  return true;
}

void TorqueController::desiredCallback(const DesiredVelocity::ConstPtr& msg) {
  if (!core::allFinite(msg->v, msg->omega, msg->v_dot, msg->omega_dot)) {
    ROS_WARN_THROTTLE(1.0, "torque_controller: rejected non-finite desired velocity (%ld so far)", ++rejected_);
    return;
  }
  if (inputs_.isRepeat(msg->header.stamp)) {  // the same period again: never integrate twice
    publishShared(torque_pub_, torque_);
    return;
  }
  if (inputs_.setSecond(*msg)) compute();
}

void TorqueController::compute() {
  const nav_msgs::Odometry& odom = inputs_.first();
  const DesiredVelocity& d = inputs_.second();
  const core::VelocityCommand cmd{d.v, d.omega, d.v_dot, d.omega_dot};
  if (stale_) {  // input is back after a gap: restart the sliding integrals, keep the estimates
    smc_->resetSurfaces();
    stale_ = false;
    ROS_INFO("torque_controller: desired_velocity is back at t = %.3f s: resuming", odom.header.stamp.toSec());
  }
  const core::SlidingModeOutput out =
      smc_->update(cmd, odom.twist.twist.linear.x, odom.twist.twist.angular.z, dt_);
  torque_.header.stamp = odom.header.stamp;
  torque_.right = out.torques.right;
  torque_.left = out.torques.left;
  publishShared(torque_pub_, torque_);
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
  publishShared(state_pub_, state_);
}

}  // namespace sowing_robot
