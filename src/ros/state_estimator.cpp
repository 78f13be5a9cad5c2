#include "sowing_robot/ros/state_estimator.h"

#include <cmath>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/settings/node_settings.h"
#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/msg_checks.h"
#include "sowing_robot/ros/common/node_failure.h"

namespace sowing_robot {
namespace {

/// Variance of a message's covariance entry; "unknown" (negative, or not finite) as 0 (the estimator's
/// process noise then stands alone).
double knownVariance(double v) { return std::isfinite(v) && v > 0.0 ? v : 0.0; }

}  // namespace

struct StateEstimator::Loaded {
  core::EkfParams params;
  double half_track = 0.0;  // [m] the URDF's nominal L: turns the wheels' increments into a heading change
  std::unique_ptr<core::FixParams> fix_schedule;  // lockstep with fix_source: when the plant measures fixes
  bool lockstep = false;
};

StateEstimator::Loaded StateEstimator::loadParams(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  p.allow("robot_description");
  const core::RunSettings run = loadRunSettings(nh, p);
  Loaded out;
  out.lockstep = run.lockstep;
  core::RobotParams robot;
  const std::string robot_error = loadRobotParams(pnh, robot);
  core::StateEstimatorSettings settings;
  loadTable(p, core::StateEstimatorSettings::table(), settings);
  loadTable(p, core::ekfTable(), out.params);
  std::string schedule_error;
  if (!settings.fix_source.empty() && run.lockstep) {
    // Another node's keys, read but not owned: plant_sim checks them (and refuses unknown ones) itself.
    ParamReader source(ros::NodeHandle(nh, settings.fix_source));
    core::SensorParams sensors;
    loadTable(source, core::sensorsTable(), sensors);
    schedule_error = core::firstError({source.error(), sensors.validate()});
    if (!schedule_error.empty()) schedule_error = "fix_source " + settings.fix_source + ": " + schedule_error;
    out.fix_schedule = std::make_unique<core::FixParams>(sensors.fix);
  }
  requireValid(p, core::firstError({robot_error, robot_error.empty() ? robot.validate() : "", settings.validate(),
                                    out.params.validate(), schedule_error}));
  out.half_track = robot.L;
  logSettings("state_estimator", core::StateEstimatorSettings::table(), settings);
  logSettings("state_estimator", core::ekfTable(), out.params);
  if (out.fix_schedule)
    ROS_INFO("state_estimator: lockstep: each step waits for the fixes due by it (%s's fix at %.3f Hz)",
             settings.fix_source.c_str(), out.fix_schedule->rate);
  else if (!settings.fix_source.empty())
    ROS_INFO("state_estimator: fix_source %s ignored: not in lockstep", settings.fix_source.c_str());
  return out;
}

StateEstimator::StateEstimator(ros::NodeHandle nh, ros::NodeHandle pnh)
    : StateEstimator(nh, pnh, loadParams(nh, pnh)) {}

StateEstimator::StateEstimator(ros::NodeHandle nh, ros::NodeHandle pnh, const Loaded& loaded)
    : ekf_(loaded.params, loaded.half_track),
      fixes_(loaded.params.fix_delay),
      increment_covariance_(core::encoderIncrementCovariance(loaded.params.increment_sigma, loaded.half_track)) {
  if (loaded.fix_schedule) await_ = std::make_unique<core::FixAwait>(*loaded.fix_schedule, loaded.params.fix_delay);
  filtered_pub_ = nh.advertise<nav_msgs::Odometry>("odometry/filtered", kLockstepQueue);
  const auto hints = ros::TransportHints().tcpNoDelay();
  odom_sub_ = nh.subscribe("odom", kLockstepQueue, &StateEstimator::odomCallback, this, hints);
  imu_sub_ = nh.subscribe("imu", kLockstepQueue, &StateEstimator::imuCallback, this, hints);
  fix_sub_ = nh.subscribe("fix", 1000, &StateEstimator::fixCallback, this, hints);
  // last: everything is subscribed (ready_roster.h); the fixes are awaited in lockstep, so their link too
  ready_ = ReadyAnnouncer(nh, pnh, loaded.lockstep,
                          await_ ? std::vector<ros::Subscriber>{odom_sub_, imu_sub_, fix_sub_}
                                 : std::vector<ros::Subscriber>{odom_sub_, imu_sub_});
}

StateEstimator::~StateEstimator() {
  const core::FixCounts& c = ekf_.counts();
  ROS_INFO(
      "state_estimator: fixes applied %ld, refused %ld (older than the history %ld, newer than the estimate "
      "%ld, invalid %ld, gated %ld), re-anchored %ld, slip onsets %ld, applied late %ld, lost from a full queue %ld, "
      "awaited but never received %ld; inputs rejected %ld",
      c.applied, c.refused(), c.too_old, c.future, c.invalid, c.gated, c.reanchored, c.slip_onsets, late_fixes_,
      fixes_.dropped(), lost_fixes_, rejected_inputs_);
  if (ekf_.params().slip.detect) {
    const core::SlipCounts s = ekf_.slipCounts();
    ROS_INFO(
        "state_estimator: slip-aware (estimator/slip/detect): a wheel loose %ld time(s), the fixes' slip alarms "
        "%ld, a wheel slipping for %.1f s",
        s.loose, s.by_fixes, s.time);
  }
}

void StateEstimator::odomCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  if (!odomIsFinite(*msg)) {
    ROS_WARN_THROTTLE(1.0, "state_estimator: rejected non-finite odom (%ld so far)", ++rejected_inputs_);
    return;
  }
  if (inputs_.isRepeat(msg->header.stamp)) {
    if (held_.empty()) {  // the plant asked again: answer with the same numbers
      publishShared(filtered_pub_, filtered_);
      return;
    }
    // The plant gave up waiting for the answer (plant_sim/lockstep_retry): the fix held for is not coming.
    // Go on without it rather than stall the run.
    const double t = held_.front().odom.header.stamp.toSec();
    double stamp = 0.0;
    await_->waiting(t, stamp);
    const int lost = await_->giveUp(t);
    lost_fixes_ += lost;
    ROS_ERROR(
        "state_estimator: the fix stamped %.3f s never came (%d awaited for the step at t=%.3f s): going on without "
        "it (is fix connected, and are fix_source's sensors/fix keys the plant's?)",
        stamp, lost, t);
    runHeld();
    return;
  }
  if (inputs_.setFirst(*msg)) paired();
}

void StateEstimator::imuCallback(const sensor_msgs::Imu::ConstPtr& msg) {
  if (!std::isfinite(msg->angular_velocity.z)) {
    ROS_WARN_THROTTLE(1.0, "state_estimator: rejected non-finite imu (%ld so far)", ++rejected_inputs_);
    return;
  }
  if (inputs_.setSecond(*msg)) paired();
}

void StateEstimator::fixCallback(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& msg) {
  core::EkfFix fix;
  fix.stamp = msg->header.stamp.toSec();
  fix.xy << msg->pose.pose.position.x, msg->pose.pose.position.y;
  const auto& c = msg->pose.covariance;
  fix.covariance << c[0], c[1], c[6], c[7];
  // A fix the estimate has passed already (it came later than estimator/fix/delay): still applied at
  // its stamp, at the next step, but that step could have gone either way: say so.
  if (ekf_.initialised() && fix.stamp + ekf_.params().fix_delay < ekf_.time() - 1e-6) {
    ++late_fixes_;
    ROS_WARN_THROTTLE(5.0,
                      "state_estimator: fix stamped %.3f s came after the estimate passed stamp + fix/delay (%.3f s); "
                      "raise estimator/fix/delay above the fix latency (%ld late so far)",
                      fix.stamp, ekf_.time(), late_fixes_);
  }
  fixes_.push(fix);
  if (!await_) return;
  await_->received(fix.stamp);
  runHeld();
}

void StateEstimator::paired() {
  const nav_msgs::Odometry& odom = inputs_.first();
  if (!await_) {
    step(odom, inputs_.second());
    return;
  }
  await_->step(odom.header.stamp.toSec(), !ekf_.initialised() && held_.empty());
  double stamp = 0.0;
  if (held_.empty() && !await_->waiting(odom.header.stamp.toSec(), stamp)) {
    step(odom, inputs_.second());
    return;
  }
  // Copies: the pair refers into inputs_, which the next message may prune.
  held_.push_back({odom, inputs_.second()});
}

void StateEstimator::runHeld() {
  double stamp = 0.0;
  while (!held_.empty() && !await_->waiting(held_.front().odom.header.stamp.toSec(), stamp)) {
    step(held_.front().odom, held_.front().imu);
    held_.pop_front();
  }
}

void StateEstimator::step(const nav_msgs::Odometry& odom, const sensor_msgs::Imu& imu) {
  const double t = odom.header.stamp.toSec();
  const double rate = imu.angular_velocity.z;
  if (!ekf_.initialised()) {
    // Start where the odometry starts (the plant resets it to the start pose), with the initial
    // covariance of the table.
    ekf_.reset(t, poseOf(odom));
  } else {
    const core::Pose2D a = poseOf(last_odom_), b = poseOf(odom);
    core::EkfStepInput in;
    // The increments that odometry's midpoint integration turns into this pose change.
    in.dtheta = core::wrapAngle(b.theta - a.theta);
    const double mid = a.theta + 0.5 * in.dtheta;
    double s, c;
    s = std::sin(mid);
    c = std::cos(mid);
    in.distance = (b.x - a.x) * c + (b.y - a.y) * s;
    in.covariance = increment_covariance_;  // the quantisation of the two encoders (core/estimation/ekf.h says why)
    in.has_rate = imu.angular_velocity_covariance[0] >= 0.0;  // -1: no rate in this message
    in.rate = rate;
    in.rate_variance = knownVariance(imu.angular_velocity_covariance[8]);
    if (!ekf_.predict(t, in)) {
      // Never silently: the estimate stays at the last step (its covariance still says how old).
      ROS_WARN_THROTTLE(1.0, "state_estimator: step at t=%.6f s refused (non-finite input or stamp not after %.6f s)",
                        t, ekf_.time());
      ++rejected_inputs_;
    }
  }
  for (const core::EkfFix& f : fixes_.due(ekf_.time())) ekf_.fuse(f);
  const core::FixCounts& c = ekf_.counts();
  if (c.refused() != reported_.refused() || c.reanchored != reported_.reanchored ||
      c.slip_onsets != reported_.slip_onsets) {
    ROS_WARN_THROTTLE(1.0,
                      "state_estimator: fixes refused so far: %ld older than the history, %ld newer than the "
                      "estimate, %ld invalid, %ld outside the gate (%ld applied, %ld of them re-anchoring the "
                      "position after estimator/fix/reanchor_after gated in a row); wheel slip taken %ld time(s) "
                      "(estimator/slip/inflation)%s",
                      c.too_old, c.future, c.invalid, c.gated, c.applied, c.reanchored, c.slip_onsets,
                      ekf_.slipping() ? ", slipping now" : "");
    reported_ = c;
  }
  last_odom_ = odom;
  publish(odom, imu);
}

void StateEstimator::publish(const nav_msgs::Odometry& odom, const sensor_msgs::Imu& imu) {
  const double rate = imu.angular_velocity.z;
  const core::Ekf::Vector& m = ekf_.mean();
  const core::Ekf::Matrix& p = ekf_.covariance();
  filtered_.header = odom.header;
  filtered_.child_frame_id = odom.child_frame_id;
  filtered_.pose.pose.position.x = m(core::Ekf::X);
  filtered_.pose.pose.position.y = m(core::Ekf::Y);
  filtered_.pose.pose.position.z = 0.0;
  filtered_.pose.pose.orientation = yawQuaternion(m(core::Ekf::THETA));
  // Row-major 6x6 over (x, y, z, roll, pitch, yaw); the planar filter does not know z, roll, pitch.
  auto& pc = filtered_.pose.covariance;
  pc.fill(0.0);
  const int idx[3] = {0, 1, 5};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) pc[6 * idx[i] + idx[j]] = p(i, j);
  pc[6 * 2 + 2] = pc[6 * 3 + 3] = pc[6 * 4 + 4] = 1e6;
  // Twist: the encoders' speed (slip biases it, as it does the odometry), or the slip-aware filter's ground
  // speed and its variance (Ekf::fedSpeed), and the gyro's rate less the estimated bias.
  filtered_.twist = odom.twist;
  filtered_.twist.twist.linear.x = ekf_.fedSpeed(odom.twist.twist.linear.x);
  if (ekf_.params().slip.detect) filtered_.twist.covariance[0] = ekf_.slipCovariance()(core::kSpeed, core::kSpeed);
  filtered_.twist.twist.angular.z = rate - m(core::Ekf::BIAS);
  filtered_.twist.covariance[35] =
      p(core::Ekf::BIAS, core::Ekf::BIAS) + knownVariance(imu.angular_velocity_covariance[8]);
  publishShared(filtered_pub_, filtered_);
}

}  // namespace sowing_robot
