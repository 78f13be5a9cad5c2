#include "sowing_robot/ros/kinematic_controller.h"

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/msg_checks.h"
#include "sowing_robot/ros/common/reconfigure_bridge.h"

namespace sowing_robot {

KinematicController::KinematicController(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  const core::RunSettings run = loadRunSettings(nh, p);
  core::KinematicControllerSettings settings;
  loadTable(p, core::KinematicControllerSettings::table(), settings);
  requireValid(p, settings.validate());
  input_timeout_ = settings.input_timeout;
  limiter_ = std::make_unique<core::CommandLimiter>(settings.limits);  // validated above: does not throw
  period_ = core::secondsFromNanos(run.periodNs());                    // the in-process loop's dt, to the bit
  // The factory builds the controller; the live gains (reconfigure_bridge.h; one server on the private
  // namespace) are served for the controllers that have a .cfg.
  outer_ = core::makeOuterController(settings);  // validated above: does not throw
  if (auto* kanayama = dynamic_cast<core::OuterAdapter<core::Kanayama>*>(outer_.get())) {
    kanayama_ = &kanayama->controller();
    kanayama_reconfigure_ =
        startReconfigure<KinematicControllerConfig>(pnh, core::kanayamaTable(), settings.kanayama, [this](auto& c) {
          applyReconfigure("kinematic_controller", core::kanayamaTable(), kanayama_->gains(), c,
                           [this](const core::KanayamaGains& g) { kanayama_->setGains(g); });
        });
  } else if (auto* pp = dynamic_cast<core::OuterAdapter<core::PurePursuit>*>(outer_.get())) {
    pure_pursuit_ = &pp->controller();
    pure_pursuit_reconfigure_ =
        startReconfigure<PurePursuitConfig>(pnh, core::purePursuitTable(), settings.pure_pursuit, [this](auto& c) {
          applyReconfigure("kinematic_controller", core::purePursuitTable(), pure_pursuit_->params(), c,
                           [this](const core::PurePursuitParams& p) { pure_pursuit_->setParams(p); });
        });
  }
  logSettings("kinematic_controller", core::KinematicControllerSettings::table(), settings);
  ROS_INFO("kinematic_controller: outer controller %s", core::outerName(settings.outer));
  lockstep_ = run.lockstep;  // lockstep: wait for the paired reference, never time out
  desired_pub_ = nh.advertise<DesiredVelocity>("desired_velocity", kLockstepQueue);
  error_pub_ = nh.advertise<TrackingError>("tracking_error", kLockstepQueue);
  const auto hints = ros::TransportHints().tcpNoDelay();
  // `feedback`: the state the loop closes on, remapped by the launch (feedback:= ground_truth | odometry).
  odom_sub_ = nh.subscribe("feedback", kLockstepQueue, &KinematicController::odomCallback, this, hints);
  ref_sub_ = nh.subscribe("reference", kLockstepQueue, &KinematicController::referenceCallback, this, hints);
  ready_ = ReadyAnnouncer(nh, pnh, lockstep_, {odom_sub_, ref_sub_});  // last: all subscribed (ready_roster.h)
}

void KinematicController::odomCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  if (!odomIsFinite(*msg)) {
    ROS_WARN_THROTTLE(1.0, "kinematic_controller: rejected non-finite odom (%ld so far)", ++rejected_);
    return;
  }
  if (inputs_.isRepeat(msg->header.stamp)) {  // the plant asked again: answer with the same numbers
    publishShared(desired_pub_, desired_);
    return;
  }
  if (inputs_.setFirst(*msg)) {
    compute();
    return;
  }
  if (!grid_reported_ && inputs_.secondsPassed(msg->header.stamp)) {
    // Once, not throttled: a throttle runs on simulated time, which a stalled lockstep loop never advances.
    grid_reported_ = true;
    ROS_ERROR(
        "kinematic_controller: no reference stamped t=%.9f s, but newer ones: the reference generator's "
        "control_rate does not match plant_sim's",
        msg->header.stamp.toSec());
  }
  stopIfStale(*msg);
}

void KinematicController::stopIfStale(const nav_msgs::Odometry& odom) {
  // Lockstep: the reference for this stamp is on its way (or being replayed to a restarted controller),
  // and simulated time stands still until the loop answers, so no age of it can mean the generator is
  // gone; a stop here would be a wrong answer to a state the plant waits for.
  if (lockstep_) return;
  const double age = (odom.header.stamp - (inputs_.any() ? inputs_.lastStamp() : ros::Time(0))).toSec();
  if (age <= input_timeout_) return;
  // No reference (generator dead or restarting): ask the inner loop to stop the robot and hold it.
  ROS_WARN_THROTTLE(1.0, "kinematic_controller: no reference for %.3f s (input_timeout %.3f s): commanding stop", age,
                    input_timeout_);
  desired_.header.stamp = odom.header.stamp;
  desired_.v = desired_.omega = desired_.v_dot = desired_.omega_dot = 0.0;
  desired_.hold = true;
  limiter_->reset();  // from rest when the reference is back, as after any hold
  publishShared(desired_pub_, desired_);
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
  ref.tool_down = r.tool_down != 0;
  ref.stop = r.stop != 0;
  const core::VelocityCommand cmd =
      limiter_->limit(outer_->compute(ref, pose, odom.twist.twist.linear.x, odom.twist.twist.angular.z), period_);
  desired_.header.stamp = odom.header.stamp;
  desired_.v = cmd.v;
  desired_.omega = cmd.omega;
  desired_.v_dot = cmd.v_dot;
  desired_.omega_dot = cmd.omega_dot;
  desired_.hold = cmd.hold;
  publishShared(desired_pub_, desired_);

  const core::PostureError pe = core::Kanayama::postureError(ref.pose, pose);
  error_.header.stamp = odom.header.stamp;
  core::worldErrors(ref, pose, error_.x, error_.y, error_.theta);
  error_.xe = pe.xe;
  error_.ye = pe.ye;
  error_.thetae = pe.thetae;
  publishShared(error_pub_, error_);
}

}  // namespace sowing_robot
