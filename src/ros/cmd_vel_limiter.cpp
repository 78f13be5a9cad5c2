#include "sowing_robot/ros/cmd_vel_limiter.h"

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/msg_checks.h"

namespace sowing_robot {

CmdVelLimiter::CmdVelLimiter(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  const core::RunSettings run = loadRunSettings(nh, p);
  core::CmdVelParams params;
  loadTable(p, core::CmdVelParams::table(), params);
  requireValid(p, params.validate());
  lockstep_ = run.lockstep;
  input_.emplace(params, lockstep_);  // lockstep: strict (a twist for the past is refused as late)
  logSettings("cmd_vel_limiter", core::CmdVelParams::table(), params);
  ROS_INFO("cmd_vel_limiter: %s", lockstep_ ? "lockstep: each state waits for a twist stamped at or after it on "
                                              "cmd_vel_stamped (geometry_msgs/TwistStamped)"
                                            : "realtime: twists on cmd_vel (Twist) or cmd_vel_stamped (TwistStamped)");
  desired_pub_ = nh.advertise<DesiredVelocity>("desired_velocity", kLockstepQueue);
  const auto hints = ros::TransportHints().tcpNoDelay();
  // Commands first: in lockstep a state can only be answered once its twist is here.
  twist_sub_ = nh.subscribe("cmd_vel", kLockstepQueue, &CmdVelLimiter::twistCallback, this, hints);
  stamped_sub_ = nh.subscribe("cmd_vel_stamped", kLockstepQueue, &CmdVelLimiter::stampedCallback, this, hints);
  // `feedback`: the states the inner loop closes on (remapped by the launch); their stamps are the
  // instants the inner loop needs a desired velocity for.
  state_sub_ = nh.subscribe("feedback", kLockstepQueue, &CmdVelLimiter::stateCallback, this, hints);
  ready_ = ReadyAnnouncer(nh, pnh, lockstep_, {state_sub_});  // last: all subscribed (ready_roster.h)
}

bool CmdVelLimiter::throttle(ros::WallTime& last) {
  const ros::WallTime now = ros::WallTime::now();
  if (!last.isZero() && (now - last).toSec() < 1.0) return false;
  last = now;
  return true;
}

void CmdVelLimiter::twistCallback(const geometry_msgs::Twist::ConstPtr& msg) {
  if (lockstep_) {
    if (throttle(plain_log_))
      ROS_WARN(
          "cmd_vel_limiter: lockstep pairs commands with states by stamp: a geometry_msgs/Twist on cmd_vel has none "
          "and is ignored; publish geometry_msgs/TwistStamped on cmd_vel_stamped");
    return;
  }
  offer(ros::Time().fromNSec(input_->now()), *msg, "cmd_vel");
}

void CmdVelLimiter::stampedCallback(const geometry_msgs::TwistStamped::ConstPtr& msg) {
  const bool unstamped = msg->header.stamp.isZero();
  if (unstamped && lockstep_) {
    if (throttle(unstamped_log_))
      ROS_WARN("cmd_vel_limiter: a TwistStamped stamped 0 on cmd_vel_stamped cannot be paired: ignored");
    return;
  }
  offer(unstamped ? ros::Time().fromNSec(input_->now()) : msg->header.stamp, msg->twist, "cmd_vel_stamped");
}

void CmdVelLimiter::offer(const ros::Time& stamp, const geometry_msgs::Twist& twist, const char* topic) {
  // A diff drive uses linear.x and angular.z; the other components are ignored, but a non-finite one
  // means a broken source all the same.
  const bool finite = core::allFinite(twist.linear.x, twist.linear.y, twist.linear.z, twist.angular.x, twist.angular.y,
                                      twist.angular.z);
  const core::CmdVerdict verdict =
      finite ? input_->offer(static_cast<std::int64_t>(stamp.toNSec()), twist.linear.x, twist.angular.z)
             : core::CmdVerdict::non_finite;
  if (verdict != core::CmdVerdict::accepted) {
    ++dropped_;
    if (throttle(dropped_log_))
      ROS_WARN("cmd_vel_limiter: dropped a twist on %s stamped %.6f s (v %g m/s, omega %g rad/s): %s (%ld so far)",
               topic, stamp.toSec(), twist.linear.x, twist.angular.z, core::verdictText(verdict), dropped_);
    return;
  }
  if (pending_ && input_->knownUntil(static_cast<std::int64_t>(pending_stamp_.toNSec()))) answer(pending_stamp_);
}

void CmdVelLimiter::stateCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  const ros::Time& stamp = msg->header.stamp;
  if (answered_ && stamp == last_) {  // the plant asked again: the same answer
    publishShared(desired_pub_, desired_);
    return;
  }
  if (answered_ && stamp < last_) return;  // older than one answered already
  if (lockstep_ && !input_->knownUntil(static_cast<std::int64_t>(stamp.toNSec()))) {
    // Asked again for the same state: the plant has waited lockstep_retry (wall time) for it. Said once
    // per state, not throttled: a throttle runs on simulated time, which stands still while we wait.
    if (pending_ && stamp == pending_stamp_ && !wait_reported_) {
      wait_reported_ = true;
      ROS_WARN("cmd_vel_limiter: the state at t = %.6f s waits for a twist stamped at or after it on cmd_vel_stamped",
               stamp.toSec());
    }
    if (!pending_ || stamp != pending_stamp_) wait_reported_ = false;
    pending_ = true;
    pending_stamp_ = stamp;
    return;
  }
  answer(stamp);
}

void CmdVelLimiter::answer(const ros::Time& stamp) {
  pending_ = false;
  const core::VelocityCommand c = input_->update(static_cast<std::int64_t>(stamp.toNSec()));
  answered_ = true;
  last_ = stamp;
  desired_.header.stamp = stamp;
  desired_.v = c.v;
  desired_.omega = c.omega;
  desired_.v_dot = c.v_dot;
  desired_.omega_dot = c.omega_dot;
  publishShared(desired_pub_, desired_);
  // Once per change, not per state: stale from cmd_vel_timeout after the command in force.
  if (input_->stale() != stale_reported_) {
    stale_reported_ = input_->stale();
    if (stale_reported_)
      ROS_WARN("cmd_vel_limiter: no fresh command for %.3f s (cmd_vel_timeout %.3f s): ramping to a stop at t = %.3f s",
               input_->age(), input_->params().timeout, stamp.toSec());
    else
      ROS_INFO("cmd_vel_limiter: commands are back at t = %.3f s", stamp.toSec());
  }
}

}  // namespace sowing_robot
