#include "sowing_robot/ros/torque_controller.h"

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/msg_checks.h"
#include "sowing_robot/ros/common/reconfigure_bridge.h"

namespace sowing_robot {

TorqueController::TorqueController(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  core::RobotParams robot;
  p.allow("robot_description");  // a private URDF may override the global one
  const std::string robot_error = loadRobotParams(pnh, robot);
  const core::RunSettings run = loadRunSettings(nh, p, {"mode"});  // our mode is atsmc | tsmc
  core::TorqueControllerSettings settings;
  loadTable(p, core::TorqueControllerSettings::table(), settings);
  core::TractionControlParams traction;  // traction_control/...: off by default
  loadTable(p, core::tractionControlTable(), traction);
  core::HitchControlParams hitch;  // hitch_control/...: off by default
  loadTable(p, core::hitchControlTable(), hitch);
  std::string hitch_error = hitch.validate();
  if (hitch_error.empty() && hitch.enabled && !traction.enabled)  // as LoopConfig::validate()
    hitch_error = "hitch_control/enabled needs traction_control/enabled (the hitch acts on its grip verdict)";
  requireValid(
      p, robot_error.empty() ? core::firstError({settings.validate(), traction.validate(), hitch_error}) : robot_error);
  const core::SlidingModeParams& params = settings.sliding;
  input_timeout_ = settings.input_timeout;
  lockstep_ = run.lockstep;  // lockstep: wait for the paired desired velocity, never time out
  dt_ = core::secondsFromNanos(run.periodNs());
  // Validated above, so the factory does not throw.
  inner_ = core::makeInnerController(settings, robot);
  if (auto* smc = dynamic_cast<core::InnerAdapter<core::SlidingModeController>*>(inner_.get()))
    smc_ = &smc->controller();
  else if (auto* pid = dynamic_cast<core::InnerAdapter<core::WheelPid>*>(inner_.get()))
    pid_ = &pid->controller();
  // The brake at a stop (validated above), at the motor's limit.
  hold_max_torque_ = params.max_torque;
  hold_ = std::make_unique<core::StandstillHold>(settings.hold, robot, params.max_torque);
  logSettings("torque_controller", core::TorqueControllerSettings::table(), settings);
  logSettings("torque_controller", core::tractionControlTable(), traction);
  if (traction.enabled) {
    traction_control_.emplace(traction, robot.L);  // validated above
    traction_monitor_.emplace(traction);
    L_ = robot.L;
  }
  if (hitch.enabled) {
    logSettings("torque_controller", core::hitchControlTable(), hitch);
    hitch_.emplace(hitch);  // validated above
  }
  ROS_INFO("torque_controller: inner controller %s; m0_hat starts at %.4f kg, I0_hat at %.5f kg m^2; %.0f Hz",
           settings.innerName().c_str(), inner_->m0Hat(), inner_->i0Hat(), 1.0 / dt_);
  state_.mode = settings.innerName();
  // Live gains of the controller in use, for the controllers that have a .cfg (one server: both would be
  // on the node's private namespace).
  if (smc_) {
    smc_reconfigure_ = startReconfigure<TorqueControllerConfig>(pnh, core::slidingModeTable(), params, [this](auto& c) {
      applyReconfigure("torque_controller", core::slidingModeTable(), smc_->params(), c,
                       [this](const core::SlidingModeParams& p) { smc_->setParams(p); });
    });
  } else if (pid_) {
    pid_reconfigure_ = startReconfigure<WheelPidConfig>(pnh, core::wheelPidTable(), settings.pid, [this](auto& c) {
      applyReconfigure("torque_controller", core::wheelPidTable(), pid_->params(), c,
                       [this](const core::WheelPidParams& p) { pid_->setParams(p); });
    });
  }
  torque_pub_ = nh.advertise<WheelTorque>("wheel_torque", kLockstepQueue);
  state_pub_ = pnh.advertise<TorqueControllerState>("state", kLockstepQueue);
  const auto hints = ros::TransportHints().tcpNoDelay();
  // `feedback`: the state the loop closes on, remapped by the launch (feedback:= ground_truth | odometry).
  odom_sub_ = nh.subscribe("feedback", kLockstepQueue, &TorqueController::odomCallback, this, hints);
  if (traction_control_) {
    // Latched: the generator's governor needs every verdict, and the first may go out before its link is up (the
    // loop cannot pass that period without it, so the latched one is the one it waits for).
    traction_pub_ = nh.advertise<TractionControlState>("traction_control/state", kLockstepQueue, true);
    fed_is_odom_ = nh.resolveName("feedback") == nh.resolveName("odom");
    // Fed neither the encoders nor the truth: the EKF's estimate (feedback:=fused), as the in-process loop decides.
    hold_on_wheels_ = !fed_is_odom_ && nh.resolveName("feedback") != nh.resolveName("ground_truth");
    if (!fed_is_odom_)
      encoder_sub_ = nh.subscribe("odom", kLockstepQueue, &TorqueController::encoderCallback, this, hints);
    ROS_INFO("torque_controller: traction control on: wheel speeds from %s, ground speed from %s",
             nh.resolveName("odom").c_str(), nh.resolveName("feedback").c_str());
  }
  desired_sub_ = nh.subscribe("desired_velocity", kLockstepQueue, &TorqueController::desiredCallback, this, hints);
  ready_ = ReadyAnnouncer(nh, pnh, lockstep_, {odom_sub_, desired_sub_, encoder_sub_});  // last: all subscribed
}

void TorqueController::odomCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  if (!odomIsFinite(*msg)) {
    ROS_WARN_THROTTLE(1.0, "torque_controller: rejected non-finite odom (%ld so far)", ++rejected_);
    return;
  }
  if (!traction_control_ || fed_is_odom_) {
    feed(*msg, *msg);
  } else if (fed_encoders_.setFirst(*msg)) {
    feed(fed_encoders_.first(), fed_encoders_.second());
  } else {
    holdZeroIfStale(*msg);
  }
}

void TorqueController::encoderCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  if (!odomIsFinite(*msg)) {
    ROS_WARN_THROTTLE(1.0, "torque_controller: rejected non-finite odom (%ld so far)", ++rejected_);
    return;
  }
  if (fed_encoders_.setSecond(*msg)) feed(fed_encoders_.first(), fed_encoders_.second());
}

void TorqueController::feed(const nav_msgs::Odometry& fed, const nav_msgs::Odometry& encoders) {
  if (traction_control_) {
    // R W of each wheel as the in-process loop forms it from the encoders' odometry (configured_run.cpp).
    const double v = encoders.twist.twist.linear.x, w = encoders.twist.twist.angular.z;
    wheel_speeds_.push_back({fed.header.stamp, v + L_ * w, v - L_ * w});
    if (wheel_speeds_.size() > 32) wheel_speeds_.pop_front();
  }
  if (inputs_.setFirst(fed)) {
    compute();
  } else {
    holdZeroIfStale(fed);
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
  ROS_WARN_THROTTLE(1.0, "torque_controller: no desired_velocity for %.3f s (input_timeout %.3f s): zero torque", age,
                    input_timeout_);
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
  // No traction (closed_loop.h): from the period after the verdict the hold, whatever the plan asks.
  const bool no_traction = traction_monitor_ && traction_monitor_->detected();
  const core::VelocityCommand cmd =
      no_traction ? core::holdCommand() : core::VelocityCommand{d.v, d.omega, d.v_dot, d.omega_dot, d.hold != 0};
  if (stale_) {  // input is back after a gap: restart the integrals (sliding mode: keep the estimates)
    if (smc_)
      smc_->resetSurfaces();
    else
      inner_->reset();
    stale_ = false;
    ROS_INFO("torque_controller: desired_velocity is back at t = %.3f s: resuming", odom.header.stamp.toSec());
  }
  const double v = odom.twist.twist.linear.x, omega = odom.twist.twist.angular.z;
  core::InnerOutput out = inner_->update(cmd, v, omega, dt_);
  if (out.holding) {  // a stop: the inner loop is frozen, the brake holds the robot (closed_loop.h, step 4)
    if (!holding_) hold_->engage();  // the robot is held where the hold began
    double hold_v = v;
    if (hold_on_wheels_) {  // the encoders' wheel speeds of this state (paired with it by feed())
      while (!wheel_speeds_.empty() && wheel_speeds_.front().stamp < odom.header.stamp) wheel_speeds_.pop_front();
      if (!wheel_speeds_.empty() && wheel_speeds_.front().stamp == odom.header.stamp)
        hold_v = core::StandstillHold::wheelSpeed(wheel_speeds_.front().right, wheel_speeds_.front().left);
    }
    const core::HoldTorques h = hold_->update(hold_v, omega, dt_);
    out.torques = h.torques;
    out.u1 = h.u1;
    out.u2 = h.u2;
    out.saturated = h.saturated;
  }
  holding_ = out.holding;
  core::WheelTorques sent = out.torques;
  if (traction_control_) {
    sent = limitTraction(out.torques, odom, !cmd.hold);
    // As the in-process loop (closed_loop.h, step 4): held on the wheels the brake is not capped; the inner loop
    // and the brake learn which torques were held back.
    if (out.holding && hold_on_wheels_) sent = out.torques;
    if (traction_control_->params().anti_windup) inner_->heldBack(sent);
    if (out.holding) hold_->heldBack(sent);
    // As the in-process loop (closed_loop.h): this period's verdict and the fed speed's travel decide the
    // tool for the step this torque drives.
    if (hitch_) {
      torque_.tool_raised = hitch_->update(traction_control_->limiting(), std::fabs(v) * dt_, dt_);
      // Its depth for the same step (0: no depth control, the drill's nominal), applied by plant_sim.
      torque_.tool_depth = hitch_->controlsDepth() ? hitch_->depth() : 0.0;
    }
  }
  torque_.header.stamp = odom.header.stamp;
  torque_.right = sent.right;
  torque_.left = sent.left;
  publishShared(torque_pub_, torque_);
  if (out.saturated)
    ROS_WARN_THROTTLE(2.0, "torque_controller: wheel torque saturated at %.4g N m (%ld periods so far)",
                      smc_   ? smc_->params().max_torque
                      : pid_ ? pid_->params().max_torque
                             : hold_max_torque_,
                      ++saturated_);

  state_.header.stamp = odom.header.stamp;
  state_.e_v = out.e_v;
  state_.e_omega = out.e_omega;
  state_.s_v = out.s_v;
  state_.s_omega = out.s_omega;
  state_.m0_hat = inner_->m0Hat();
  state_.i0_hat = inner_->i0Hat();
  state_.u1 = out.u1;
  state_.u2 = out.u2;
  state_.saturated = out.saturated;
  state_.holding = out.holding;
  publishShared(state_pub_, state_);
}

core::WheelTorques TorqueController::limitTraction(const core::WheelTorques& requested, const nav_msgs::Odometry& fed,
                                                   bool driving) {
  while (!wheel_speeds_.empty() && wheel_speeds_.front().stamp < fed.header.stamp) wheel_speeds_.pop_front();
  if (wheel_speeds_.empty() || wheel_speeds_.front().stamp != fed.header.stamp) {
    // Cannot happen: a fed state reaches the pair only with its encoders' message (feed()).
    ROS_ERROR_THROTTLE(1.0, "torque_controller: no wheel speeds for t = %.6f s: traction control skipped",
                       fed.header.stamp.toSec());
    return requested;
  }
  const WheelSpeeds& w = wheel_speeds_.front();
  const core::WheelGroundSpeeds m{w.right, w.left, fed.twist.twist.linear.x, fed.twist.twist.angular.z};
  const core::WheelTorques sent = traction_control_->limit(requested, m, dt_);
  traction_state_.header.stamp = fed.header.stamp;
  traction_state_.slip_right = traction_control_->slip(0);
  traction_state_.slip_left = traction_control_->slip(1);
  traction_state_.ceiling_right = traction_control_->ceiling(0);
  traction_state_.ceiling_left = traction_control_->ceiling(1);
  traction_state_.requested_right = requested.right;
  traction_state_.requested_left = requested.left;
  traction_state_.slipping = traction_control_->slipping();
  traction_state_.limiting = traction_control_->limiting();
  // The progress check, after the limit as in the in-process loop (closed_loop.h): its verdict holds the robot
  // from the next period on.
  if (traction_monitor_ && !traction_monitor_->detected() &&
      traction_monitor_->update(loopSeconds(fed.header.stamp), poseOf(fed), driving, traction_control_->slippingAsFed(),
                                dt_)) {
    traction_state_.no_traction = true;
    traction_state_.no_traction_report = traction_monitor_->report().text();
    traction_state_.no_traction_where.x = traction_monitor_->report().where.x;
    traction_state_.no_traction_where.y = traction_monitor_->report().where.y;
    ROS_ERROR(
        "torque_controller: %s; the robot is held from now on, and the run ends %.3f s later "
        "(traction_control/no_traction_hold)",
        traction_state_.no_traction_report.c_str(), traction_control_->params().no_traction_hold);
  }
  publishShared(traction_pub_, traction_state_);  // before the torque: the governor's input for the next reference
  return sent;
}

}  // namespace sowing_robot
