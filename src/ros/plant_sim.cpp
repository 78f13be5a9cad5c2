#include "sowing_robot/ros/plant_sim.h"

#include <rosgraph_msgs/Clock.h>

#include <cmath>

#include "sowing_robot/core/validation.h"
#include "sowing_robot/ros/component_params.h"
#include "sowing_robot/ros/msg_checks.h"

namespace sowing_robot {

namespace {
ros::Time stampOf(std::int64_t k, std::int64_t period_ns) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(k * period_ns));
  return t;
}
}  // namespace

PlantSim::PlantSim(ros::NodeHandle nh, ros::NodeHandle pnh) : nh_(nh) {
  ParamReader p(pnh);
  core::RobotParams robot;
  p.allow("robot_description");  // a private URDF may override the global one
  std::string error = loadRobotParams(pnh, robot);
  const std::string mode = p.get("mode", "realtime");
  if (error.empty() && mode != "realtime" && mode != "lockstep")
    error = "mode = '" + mode + "' must be 'realtime' or 'lockstep'";
  cfg_.lockstep = mode == "lockstep";
  cfg_.period_ns = loadControlPeriod(p, error);
  cfg_.duration = p.get("duration", cfg_.duration);
  cfg_.realtime_factor = p.get("realtime_factor", cfg_.realtime_factor);
  cfg_.torque_timeout = p.get("torque_timeout", cfg_.torque_timeout);
  cfg_.publish_rate = p.get("publish_rate", cfg_.publish_rate);
  cfg_.clock_rate = p.get("clock_rate", cfg_.clock_rate);
  cfg_.lockstep_retry = p.get("lockstep_retry", cfg_.lockstep_retry);
  cfg_.lockstep_timeout = p.get("lockstep_timeout", cfg_.lockstep_timeout);
  cfg_.lockstep_give_up = p.get("lockstep_give_up", cfg_.lockstep_give_up);
  cfg_.min_subscribers = p.get("min_subscribers", cfg_.min_subscribers);
  cfg_.startup_delay = p.get("startup_delay", cfg_.startup_delay);
  cfg_.max_speed = p.get("max_speed", cfg_.max_speed);
  cfg_.exit_at_end = p.get("exit_at_end", cfg_.exit_at_end);
  start_ = loadStartPose(p);
  const core::PlantDisturbance disturbance = loadDisturbance(p);
  if (error.empty())
    error = core::firstError(
        {robot.validate(), disturbance.validate(), core::checkRange("duration", cfg_.duration, 0.0, 1e7, "s"),
         core::checkRange("realtime_factor", cfg_.realtime_factor, 0.01, 1000.0),
         core::checkPositive("torque_timeout", cfg_.torque_timeout, "s"),
         core::checkRange("publish_rate", cfg_.publish_rate, 0.1, 1000.0, "Hz"),
         core::checkRange("clock_rate", cfg_.clock_rate, 0.0, 1e6, "Hz"),
         core::checkPositive("lockstep_retry", cfg_.lockstep_retry, "s"),
         core::checkPositive("lockstep_timeout", cfg_.lockstep_timeout, "s"),
         core::checkNonNegative("lockstep_give_up", cfg_.lockstep_give_up, "s"),
         core::checkRange("min_subscribers", cfg_.min_subscribers, 0, 100),
         core::checkNonNegative("startup_delay", cfg_.startup_delay, "s"),
         core::checkPositive("max_speed", cfg_.max_speed, "m/s"),
         core::allFinite(start_.x, start_.y, start_.theta) ? "" : "start pose must be finite"});
  requireValid(p, error);

  plant_ = std::make_unique<core::Plant>(robot, disturbance);
  core::State x0 = core::State::Zero();
  x0[core::X] = start_.x;
  x0[core::Y] = start_.y;
  x0[core::THETA] = start_.theta;
  plant_->reset(x0, 0.0);
  visual_every_ = std::max<std::int64_t>(1, std::llround(1e9 / cfg_.publish_rate / cfg_.period_ns));
  if (cfg_.clock_rate > 0.0)
    clock_every_ = std::max<std::int64_t>(1, std::llround(1e9 / cfg_.clock_rate / cfg_.period_ns));

  ROS_INFO("plant_sim: %s mode, %.0f Hz, duration %.3f s, m0 %.4f kg (true %.4f), I0 %.5f kg m^2 (true %.5f), "
           "sinusoidal disturbance %s, noise std %.3f N m, start (%.3f, %.3f, %.3f)",
           mode.c_str(), 1e9 / cfg_.period_ns, cfg_.duration, robot.m0(), plant_->trueM0(), robot.I0(),
           plant_->trueI0(), disturbance.sinusoidal ? "on" : "off", disturbance.noise_std, start_.x, start_.y,
           start_.theta);

  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", kLockstepQueue);
  joint_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
  path_pub_ = nh_.advertise<nav_msgs::Path>("travelled_path", 1, true);
  ros::SubscribeOptions torque_options = ros::SubscribeOptions::create<WheelTorque>(
      "wheel_torque", 50, [this](const WheelTorque::ConstPtr& m) { torqueCallback(m); }, ros::VoidPtr(),
      &torque_queue_);
  torque_options.transport_hints = ros::TransportHints().tcpNoDelay();
  torque_sub_ = nh_.subscribe(torque_options);

  odom_msg_.header.frame_id = "odom";
  odom_msg_.child_frame_id = "base_link";
  joint_msg_.name = {"right_wheel_joint", "left_wheel_joint"};
  joint_msg_.position.resize(2);
  joint_msg_.velocity.resize(2);
}

void PlantSim::torqueCallback(const WheelTorque::ConstPtr& msg) {
  if (!core::allFinite(msg->right, msg->left)) {
    ++rejected_;
    ROS_WARN_THROTTLE(1.0, "plant_sim: rejected non-finite wheel torque (right %f, left %f); %ld so far",
                      msg->right, msg->left, static_cast<long>(rejected_));
    return;
  }
  if (cfg_.lockstep) {
    if (msg->header.stamp != waiting_for_) {
      if (msg->header.stamp < waiting_for_) {
        ++late_;
        ROS_WARN_THROTTLE(1.0, "plant_sim: late wheel torque for t=%.6f while at t=%.6f ignored (%ld so far)",
                          msg->header.stamp.toSec(), waiting_for_.toSec(), static_cast<long>(late_));
      }
      return;
    }
    if (got_torque_) return;  // a repeat of the same answer
  }
  torque_ = {msg->right, msg->left};
  torque_stamp_ = msg->header.stamp;
  torque_valid_ = true;
  got_torque_ = true;
}

namespace {
// An empty callback: queued by stop() to end run()'s wait on the torque queue at once.
class WakeUp : public ros::CallbackInterface {
 public:
  CallResult call() override { return Success; }
};
}  // namespace

void PlantSim::stop() {
  stop_ = true;
  torque_queue_.addCallback(boost::make_shared<WakeUp>());
}

void PlantSim::publishState(const ros::Time& stamp, bool visuals) {
  // Nothing in the control loop reads /clock (every node works on header stamps); it serves ROS time
  // for logs, rosbag and rviz, so it may be published less often than every step (clock_rate).
  if (step_ % clock_every_ == 0 || visuals) {
    rosgraph_msgs::Clock clock;
    clock.clock = stamp;
    clock_pub_.publish(clock);
  }
  const core::State& s = plant_->state();
  odom_msg_.header.stamp = stamp;
  odom_msg_.pose.pose.position.x = s[core::X];
  odom_msg_.pose.pose.position.y = s[core::Y];
  odom_msg_.pose.pose.orientation.z = std::sin(0.5 * s[core::THETA]);
  odom_msg_.pose.pose.orientation.w = std::cos(0.5 * s[core::THETA]);
  odom_msg_.twist.twist.linear.x = s[core::V];
  odom_msg_.twist.twist.angular.z = s[core::OMEGA];
  publishShared(odom_pub_, odom_msg_);
  if (!visuals) return;

  geometry_msgs::TransformStamped tf;
  tf.header = odom_msg_.header;
  tf.child_frame_id = "base_link";
  tf.transform.translation.x = s[core::X];
  tf.transform.translation.y = s[core::Y];
  tf.transform.rotation = odom_msg_.pose.pose.orientation;
  tf_.sendTransform(tf);

  joint_msg_.header.stamp = stamp;
  joint_msg_.position[0] = s[core::PHI_R];
  joint_msg_.position[1] = s[core::PHI_L];
  const core::State ds = plant_->derivative(s, 0.0, 0.0);  // wheel rates do not depend on torque
  joint_msg_.velocity[0] = ds[core::PHI_R];
  joint_msg_.velocity[1] = ds[core::PHI_L];
  joint_pub_.publish(joint_msg_);

  geometry_msgs::PoseStamped pose;
  pose.header = odom_msg_.header;
  pose.pose = odom_msg_.pose.pose;
  if (path_.add(pose)) path_pub_.publish(path_.path());
}

void PlantSim::requireHealthy() {
  const core::State& s = plant_->state();
  if (std::isfinite(s.sum()) && std::fabs(s[core::V]) <= cfg_.max_speed) return;
  ROS_FATAL("plant_sim: state diverged at t=%.6f s (x %g, y %g, theta %g, v %g, omega %g; max_speed %g m/s): "
            "stopping the run instead of publishing garbage",
            plant_->time(), s[core::X], s[core::Y], s[core::THETA], s[core::V], s[core::OMEGA], cfg_.max_speed);
  exitProcess(2);
}

void PlantSim::giveUpAfter(const ros::WallTime& since, const char* what) {
  if (cfg_.lockstep_give_up <= 0.0 || (ros::WallTime::now() - since).toSec() <= cfg_.lockstep_give_up) return;
  ROS_FATAL("plant_sim: lockstep gave up at t=%.6f s after %.1f s wall (lockstep_give_up) waiting for %s; "
            "%u publisher(s) on %s: is torque_controller running?",
            waiting_for_.toSec(), cfg_.lockstep_give_up, what, torque_sub_.getNumPublishers(),
            torque_sub_.getTopic().c_str());
  exitProcess(3);
}

void PlantSim::runLockstep() {
  // This thread publishes the state, serves the torque queue until the torque for that state has come,
  // and integrates: the torque callback runs here, so no other thread needs waking.
  const ros::WallTime wait_start = ros::WallTime::now();
  ros::WallTime waited = wait_start;
  while (running() && (static_cast<int>(odom_pub_.getNumSubscribers()) < cfg_.min_subscribers ||
                       torque_sub_.getNumPublishers() < 1)) {
    ros::WallDuration(0.01).sleep();
    const ros::WallTime now = ros::WallTime::now();
    if ((now - waited).toSec() > cfg_.lockstep_timeout) {
      ROS_WARN("plant_sim: lockstep waiting for the loop for %.1f s wall: %u/%d odom subscribers, %u wheel_torque "
               "publishers", (now - wait_start).toSec(), odom_pub_.getNumSubscribers(), cfg_.min_subscribers,
               torque_sub_.getNumPublishers());
      waited = now;
    }
    giveUpAfter(wait_start, "the loop to connect (odom subscribers, a wheel_torque publisher)");
  }
  ros::WallDuration(cfg_.startup_delay).sleep();
  const std::int64_t n = cfg_.duration > 0.0 ? std::llround(cfg_.duration * 1e9 / cfg_.period_ns) : -1;
  const double dt = core::secondsFromNanos(cfg_.period_ns);
  const ros::WallTime wall_start = ros::WallTime::now();
  const ros::WallDuration retry(cfg_.lockstep_retry);
  for (std::int64_t k = 0; running() && (n < 0 || k <= n); ++k) {
    const ros::Time stamp = stampOf(k, cfg_.period_ns);
    waiting_for_ = stamp;
    got_torque_ = false;
    step_ = k;
    publishState(stamp, k % visual_every_ == 0 || k == n);
    const ros::WallTime stall_start = ros::WallTime::now();
    ros::WallTime stalled_since = stall_start, sent = stall_start;
    while (running() && !got_torque_) {
      torque_queue_.callAvailable(retry);  // returns after a callback (any stamp) or the retry time
      if (got_torque_ || !running()) break;
      const ros::WallTime now = ros::WallTime::now();
      if (now - sent < retry) continue;
      publishState(stamp, false);  // a connection that came late gets the state again
      sent = now;
      if ((now - stalled_since).toSec() > cfg_.lockstep_timeout) {
        ROS_ERROR("plant_sim: lockstep stalled at t=%.6f s: no wheel_torque stamped for it after %.1f s wall "
                  "(%u publisher(s) on %s%s); waiting",
                  stamp.toSec(), (now - stall_start).toSec(), torque_sub_.getNumPublishers(),
                  torque_sub_.getTopic().c_str(),
                  torque_sub_.getNumPublishers() == 0 ? ": is torque_controller running?" : "");
        stalled_since = now;
      }
      giveUpAfter(stall_start, "a wheel_torque stamped for the current state");
    }
    const core::WheelTorques u = torque_;
    if (!running() || k == n) break;
    plant_->step(u.right, u.left, dt);
    requireHealthy();
  }
  const double wall = (ros::WallTime::now() - wall_start).toSec();
  ROS_INFO("plant_sim: lockstep scenario finished: %.3f s simulated in %.3f s wall (real-time factor %.2f); "
           "%ld late and %ld non-finite torques ignored",
           cfg_.duration, wall, wall > 0 ? cfg_.duration / wall : 0.0, static_cast<long>(late_),
           static_cast<long>(rejected_));
}

void PlantSim::runRealtime() {
  const double dt = core::secondsFromNanos(cfg_.period_ns);
  const ros::WallTime wall_start = ros::WallTime::now();
  std::int64_t slipped = 0;
  for (std::int64_t k = 0; running(); ++k) {
    const ros::Time stamp = stampOf(k, cfg_.period_ns);
    step_ = k;
    publishState(stamp, k % visual_every_ == 0);
    const ros::WallTime due = wall_start + ros::WallDuration((k + 1 - slipped) * dt / cfg_.realtime_factor);
    const ros::WallDuration remaining = due - ros::WallTime::now();
    if (remaining > ros::WallDuration(0)) {
      remaining.sleep();
    } else if (remaining < ros::WallDuration(-0.05)) {
      // More than 50 ms behind (an overloaded machine): slip the schedule instead of bursting steps,
      // which would run simulated time ahead of the controllers and trip their timeouts.
      slipped = k + 1 - static_cast<std::int64_t>((ros::WallTime::now() - wall_start).toSec() *
                                                   cfg_.realtime_factor / dt);
      ROS_WARN_THROTTLE(10.0, "plant_sim: realtime fell behind the wall clock; slipping (machine overloaded?)");
    }
    torque_queue_.callAvailable();  // every torque that came during the step; the newest is held
    core::WheelTorques u;
    const bool fresh = torque_valid_ && (stamp - torque_stamp_).toSec() <= cfg_.torque_timeout;
    if (fresh) u = torque_;
    if (!fresh && torque_valid_) {
      ROS_WARN_THROTTLE(2.0, "plant_sim: no wheel_torque for %.3f s (timeout %.3f s): applying zero torque",
                        (stamp - torque_stamp_).toSec(), cfg_.torque_timeout);
    }
    plant_->step(u.right, u.left, dt);
    requireHealthy();
  }
}

void PlantSim::run() {
  if (cfg_.lockstep)
    runLockstep();
  else
    runRealtime();
}

}  // namespace sowing_robot
