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
  const std::string robot_error = loadRobotParams(pnh, robot);
  const core::RunSettings run = loadRunSettings(nh, p);
  core::PlantSimSettings settings;
  loadTable(p, core::PlantSimSettings::table(), settings);
  requireValid(p, core::firstError({robot_error, robot_error.empty() ? robot.validate() : "", settings.validate()}));
  cfg_.lockstep = run.lockstep;
  cfg_.period_ns = run.periodNs();
  cfg_.duration = run.duration;
  cfg_.realtime_factor = settings.realtime_factor;
  cfg_.torque_timeout = settings.torque_timeout;
  cfg_.publish_rate = settings.publish_rate;
  cfg_.clock_rate = settings.clock_rate;
  cfg_.lockstep_retry = settings.lockstep_retry;
  cfg_.lockstep_timeout = settings.lockstep_timeout;
  cfg_.lockstep_give_up = settings.lockstep_give_up;
  cfg_.min_subscribers = settings.min_subscribers;
  cfg_.startup_delay = settings.startup_delay;
  cfg_.max_speed = settings.max_speed;
  cfg_.exit_at_end = settings.exit_at_end;
  start_ = settings.start();
  const core::PlantDisturbance& disturbance = settings.disturbance;

  plant_ = std::make_unique<core::Plant>(robot, disturbance);
  core::State x0 = core::State::Zero();
  x0[core::X] = start_.x;
  x0[core::Y] = start_.y;
  x0[core::THETA] = start_.theta;
  plant_->reset(x0, 0.0);
  visual_every_ = std::max<std::int64_t>(1, std::llround(1e9 / cfg_.publish_rate / cfg_.period_ns));
  if (cfg_.clock_rate > 0.0)
    clock_every_ = std::max<std::int64_t>(1, std::llround(1e9 / cfg_.clock_rate / cfg_.period_ns));

  logSettings("plant_sim", core::RunSettings::table(), run, "run/");
  logSettings("plant_sim", core::PlantSimSettings::table(), settings);
  ROS_INFO("plant_sim: m0 %.4f kg (true %.4f), I0 %.5f kg m^2 (true %.5f)", robot.m0(), plant_->trueM0(), robot.I0(),
           plant_->trueI0());

  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", kLockstepQueue);
  joint_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
  path_pub_ = nh_.advertise<nav_msgs::Path>("travelled_path", 1, true);
  ros::SubscribeOptions torque_options = ros::SubscribeOptions::create<WheelTorque>(
      "wheel_torque", 50, [this](const WheelTorque::ConstPtr& m) { torqueCallback(m); }, ros::VoidPtr(),
      cfg_.lockstep ? static_cast<ros::CallbackQueueInterface*>(&inline_queue_) : &torque_queue_);
  torque_options.transport_hints = ros::TransportHints().tcpNoDelay();
  torque_sub_ = nh_.subscribe(torque_options);

  odom_msg_.header.frame_id = run.odom_frame;
  odom_msg_.child_frame_id = run.base_frame;
  path_ = PathBuffer(run.odom_frame, 0.05, 10);  // a point every 5 cm, re-sent every 10th point
  joint_msg_.name = {"right_wheel_joint", "left_wheel_joint"};
  joint_msg_.position.resize(2);
  joint_msg_.velocity.resize(2);
}

PlantSim::~PlantSim() {
  // Returns only when no torque callback is running: roscpp holds the subscription's callback lock
  // while a callback queued on inline_queue_ runs. Not under inline_queue_'s mutex (that order would
  // be the reverse of roscpp's and could deadlock).
  torque_sub_.shutdown();
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
    // Before the first state, after the last, after a divergence, or a repeat of the same answer.
    if (step_ < 0 || got_torque_ || finished_ || diverged_ || !running()) return;
  }
  torque_ = {msg->right, msg->left};
  torque_stamp_ = msg->header.stamp;
  torque_valid_ = true;
  got_torque_ = true;
  if (cfg_.lockstep) advanceLockstep();
}

void PlantSim::advanceLockstep() {
  if (last_step_ >= 0 && step_ >= last_step_) {  // the torque for the final state: the scenario is over
    // Reported here, at once: a headless launch may end (run_monitor is done) before run() looks again.
    const double wall = (ros::WallTime::now() - wall_start_).toSec();
    ROS_INFO("plant_sim: lockstep scenario finished: %.3f s simulated in %.3f s wall (real-time factor %.2f); "
             "%ld late and %ld non-finite torques ignored",
             cfg_.duration, wall, wall > 0 ? cfg_.duration / wall : 0.0, static_cast<long>(late_),
             static_cast<long>(rejected_));
    finished_ = true;
    return;
  }
  plant_->step(torque_.right, torque_.left, core::secondsFromNanos(cfg_.period_ns));
  if (!healthy()) {
    diverged_ = true;  // run() reports it and ends the process (not from inside roscpp's callback)
    return;
  }
  publishLockstepState(step_ + 1);
}

void PlantSim::publishLockstepState(std::int64_t k) {
  step_ = k;
  waiting_for_ = stampOf(k, cfg_.period_ns);
  got_torque_ = false;
  progress_.store(k, std::memory_order_release);
  publishState(waiting_for_, k % visual_every_ == 0 || k == last_step_);
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

void PlantSim::publishState(const ros::Time& stamp, bool visuals, bool clock) {
  const core::State& s = plant_->state();
  odom_msg_.header.stamp = stamp;
  odom_msg_.pose.pose.position.x = s[core::X];
  odom_msg_.pose.pose.position.y = s[core::Y];
  odom_msg_.pose.pose.orientation = yawQuaternion(s[core::THETA]);
  odom_msg_.twist.twist.linear.x = s[core::V];
  odom_msg_.twist.twist.angular.z = s[core::OMEGA];
  publishShared(odom_pub_, odom_msg_);
  // Nothing in the control loop reads /clock (every node works on header stamps); it serves ROS time
  // for logs, rosbag and rviz, so it may go out less often than every step (clock_rate), and after the
  // state, off the loop's critical path (it has a link to every node).
  if (clock || visuals || step_ % clock_every_ == 0) {
    rosgraph_msgs::Clock c;
    c.clock = stamp;
    clock_pub_.publish(c);
  }
  if (!visuals) return;

  geometry_msgs::TransformStamped tf;
  tf.header = odom_msg_.header;
  tf.child_frame_id = odom_msg_.child_frame_id;
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

bool PlantSim::healthy() const {
  const core::State& s = plant_->state();
  return std::isfinite(s.sum()) && std::fabs(s[core::V]) <= cfg_.max_speed;
}

void PlantSim::exitDiverged() {
  const core::State& s = plant_->state();
  ROS_FATAL("plant_sim: state diverged at t=%.6f s (x %g, y %g, theta %g, v %g, omega %g; max_speed %g m/s): "
            "stopping the run instead of publishing garbage",
            plant_->time(), s[core::X], s[core::Y], s[core::THETA], s[core::V], s[core::OMEGA], cfg_.max_speed);
  exitProcess(2);
}

std::string PlantSim::torqueSources() const {
  const unsigned publishers = torque_sub_.getNumPublishers();
  return std::to_string(publishers) + " publisher(s) on " + torque_sub_.getTopic() +
         (publishers == 0 ? ": is torque_controller running?" : "");
}

void PlantSim::giveUpAfter(const ros::WallTime& since, const ros::Time& stamp, const char* what) {
  if (cfg_.lockstep_give_up <= 0.0 || (ros::WallTime::now() - since).toSec() <= cfg_.lockstep_give_up) return;
  ROS_FATAL("plant_sim: lockstep gave up at t=%.6f s after %.1f s wall (lockstep_give_up) waiting for %s; %s",
            stamp.toSec(), cfg_.lockstep_give_up, what, torqueSources().c_str());
  exitProcess(3);
}

void PlantSim::runLockstep() {
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
    giveUpAfter(wait_start, ros::Time(0), "the loop to connect (odom subscribers, a wheel_torque publisher)");
  }
  ros::WallDuration(cfg_.startup_delay).sleep();
  if (!running()) return;
  last_step_ = cfg_.duration > 0.0 ? std::llround(cfg_.duration * 1e9 / cfg_.period_ns) : -1;
  {
    std::lock_guard<std::recursive_mutex> lock(inline_queue_.mutex());
    wall_start_ = ros::WallTime::now();
    publishLockstepState(0);  // from here on the torque callback drives the steps
  }
  // Supervise: the loop needs this thread only when an answer is missing, so it looks every 10 ms.
  const ros::WallDuration retry(cfg_.lockstep_retry), poll(std::min(0.01, cfg_.lockstep_retry));
  std::int64_t seen = -1;
  ros::WallTime stall_start, stalled_since, sent;
  while (running() && !finished_) {
    poll.sleep();
    if (diverged_) exitDiverged();
    const std::int64_t k = progress_.load(std::memory_order_acquire);
    const ros::WallTime now = ros::WallTime::now();
    if (k != seen) {
      seen = k;
      stall_start = stalled_since = sent = now;
      continue;
    }
    if (now - sent < retry) continue;
    ros::Time stamp;
    {
      std::lock_guard<std::recursive_mutex> lock(inline_queue_.mutex());
      if (finished_ || diverged_ || step_ != seen) continue;
      stamp = waiting_for_;
      // A connection that came late gets the state again, and /clock with it: the reference generator,
      // paced by /clock, may be what the loop waits for (a reference generator that started late).
      publishState(stamp, false, true);
    }
    sent = now;
    if ((now - stalled_since).toSec() > cfg_.lockstep_timeout) {
      ROS_ERROR("plant_sim: lockstep stalled at t=%.6f s: no wheel_torque stamped for it after %.1f s wall "
                "(%s); waiting",
                stamp.toSec(), (now - stall_start).toSec(), torqueSources().c_str());
      stalled_since = now;
    }
    giveUpAfter(stall_start, stamp, "a wheel_torque stamped for the current state");
  }
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
    if (!healthy()) exitDiverged();
  }
}

void PlantSim::run() {
  if (cfg_.lockstep)
    runLockstep();
  else
    runRealtime();
}

}  // namespace sowing_robot
