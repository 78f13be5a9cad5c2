#include "sowing_robot/ros/run_monitor.h"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/control/traction_control.h"
#include "sowing_robot/core/simulation/lockstep.h"
#include "sowing_robot/core/simulation/runner.h"
#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/failure_log.h"
#include "sowing_robot/ros/common/msg_checks.h"

namespace sowing_robot {

RunMonitor::RunMonitor(ros::NodeHandle nh, ros::NodeHandle pnh) : pnh_(pnh) {
  ParamReader p(pnh);
  const core::RunSettings run = loadRunSettings(nh, p);
  core::RunMonitorSettings settings;
  loadTable(p, core::RunMonitorSettings::table(), settings);
  requireValid(p, core::firstError({settings.validate(), core::checkPositive("run/duration", run.duration, "s")}));
  duration_ = run.duration;
  if (run.lockstep) expected_samples_ = core::lockstepLastStep(duration_, run.periodNs()) + 1;  // as plant_sim stops
  output_ = settings.output;
  label_ = settings.label;
  exit_at_end_ = settings.exit_at_end;
  // resolved in the node's namespace (a fleet robot's recorder is robot_<i>/recorder), and named so in the log
  recorder_topic_ = settings.recorder.empty() ? "" : nh.resolveName(settings.recorder);
  recorder_timeout_ = settings.recorder_timeout;
  // The time-domain figures (rise, settling, overshoot) need every sample: 32 B per period, ~115 MB per
  // hour at 1 kHz. Long runs (soak) switch them off and keep only the integrals (constant memory).
  metrics_ = core::MetricsAccumulator(settings.time_domain);
  metrics_.reserve(static_cast<std::size_t>(duration_ * 1000.0) + 2);
  // Subscribed from the start: the recorder's latched stamp is then already here when the run ends.
  if (!recorder_topic_.empty()) recorder_sub_ = nh.subscribe(recorder_topic_, 10, &RunMonitor::recordedCallback, this);
  status_pub_ = pnh.advertise<std_msgs::String>("status", 1, true);
  // Latched: the plan in force when the run ends says whether the field was completed or stopped short of.
  plan_sub_ = nh.subscribe("plan", 1, &RunMonitor::planCallback, this);
  const auto hints = ros::TransportHints().tcpNoDelay();
  truth_sub_ = nh.subscribe("ground_truth", kLockstepQueue, &RunMonitor::truthCallback, this, hints);
  ref_sub_ = nh.subscribe("reference", kLockstepQueue, &RunMonitor::referenceCallback, this, hints);
  std::vector<ros::Subscriber> awaited{truth_sub_, ref_sub_};
  // With the traction control the run may end on its no-traction verdict (torque_controller's keys).
  bool traction_control = false;
  nh.param("torque_controller/traction_control/enabled", traction_control, false);
  if (traction_control) {
    nh.param("torque_controller/traction_control/no_traction_hold", no_traction_hold_,
             core::TractionControlParams().no_traction_hold);
    gated_ = run.lockstep;
    traction_sub_ = nh.subscribe("traction_control/state", kLockstepQueue, &RunMonitor::tractionCallback, this, hints);
    awaited.push_back(traction_sub_);
  }
  ready_ = ReadyAnnouncer(nh, pnh, run.lockstep, awaited);  // last: all subscribed (ready_roster.h)
}

void RunMonitor::truthCallback(const nav_msgs::Odometry::ConstPtr& msg) {
  if (done_) return;
  if (inputs_.setFirst(*msg)) addPair();
}

void RunMonitor::referenceCallback(const ReferenceState::ConstPtr& msg) {
  if (done_) return;
  if (inputs_.setSecond(*msg)) addPair();
}

void RunMonitor::addPair() {
  const nav_msgs::Odometry& truth = inputs_.first();
  const ReferenceState& r = inputs_.second();
  const ros::Time stamp = truth.header.stamp;
  if (metrics_.samples() > 0 && stamp <= last_) return;  // repeats answer a retried state
  if (!held_.empty() && stamp <= held_.back().stamp) return;
  core::Reference ref;
  ref.pose = {r.x, r.y, r.theta};
  double ex, ey, eth;
  core::worldErrors(ref, poseOf(truth), ex, ey, eth);
  if (!gated_) {
    score(stamp, ex, ey, eth);
    return;
  }
  held_.push_back(Held{stamp, ex, ey, eth});
  flush();
}

void RunMonitor::score(const ros::Time& stamp, double ex, double ey, double eth) {
  if (!metrics_.add(stamp.toSec(), ex, ey, eth)) {  // refuses non-finite errors
    ROS_WARN_THROTTLE(1.0, "run_monitor: non-finite tracking error ignored");
    return;
  }
  last_ = stamp;
  // The in-process loop's end (closed_loop.h): the first period at or past the verdict + no_traction_hold.
  const double t = loopSeconds(stamp);
  if (end_at_ && t >= *end_at_) {
    ROS_ERROR("run_monitor: the run ends at t = %.3f s: %s (torque_controller)", t, no_traction_.c_str());
    finish();
    return;
  }
  if (stamp.toSec() >= duration_ - 1e-9) finish();
}

void RunMonitor::tractionCallback(const TractionControlState::ConstPtr& msg) {
  if (done_) return;
  if (msg->no_traction && !end_at_) {
    end_at_ = loopSeconds(msg->header.stamp) + no_traction_hold_;
    no_traction_ = msg->no_traction_report;
  }
  if (msg->header.stamp > traction_until_) traction_until_ = msg->header.stamp;
  flush();
}

void RunMonitor::planCallback(const FieldPlan::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(wait_mutex_);
  plan_status_ = msg->status;
  plan_reason_ = msg->reason;
}

void RunMonitor::flush() {
  while (!done_ && !held_.empty() && held_.front().stamp <= traction_until_) {
    const Held h = held_.front();
    held_.pop_front();
    score(h.stamp, h.ex, h.ey, h.eth);
  }
}

void RunMonitor::finish() {
  done_ = true;
  const auto m = metrics_.result();
  // The table goes to stdout once, as plain text (it used to be logged with ROS_INFO as well, so every
  // run printed it twice).
  ROS_INFO("run_monitor: %zu samples up to t = %.3f s", metrics_.samples(), last_.toSec());
  // In lockstep every period is stepped once, so a missing one is a lost message, not timing: say so
  // rather than hand out metrics that quietly differ from the same run's.
  const auto samples = static_cast<std::int64_t>(metrics_.samples());
  if (expected_samples_ > 0 && samples != expected_samples_ && !end_at_)
    ROS_ERROR(
        "run_monitor: %ld of the run's %ld periods were scored (%zu messages dropped unpaired): the metrics "
        "miss the rest",
        samples, expected_samples_, inputs_.dropped());
  else if (inputs_.dropped() > 0)
    ROS_WARN("run_monitor: %zu messages dropped unpaired", inputs_.dropped());
  std_msgs::String status;
  char at[64];
  std::snprintf(at, sizeof at, "t = %.3f s", last_.toSec());
  {
    // How the run ended, as the exit code (node_failure.h): no traction (5), the plan stopped short of its field
    // (6: stopped_short or no_safe_way, the robot held at the stop), or completed (0).
    std::lock_guard<std::mutex> lock(wait_mutex_);
    const bool short_of_field = plan_status_ == "stopped_short" || plan_status_ == "no_safe_way";
    if (end_at_)
      status.data = no_traction_ + "; ended at " + at;
    else if (short_of_field)
      status.data = plan_status_ + ": " + plan_reason_ + "; ended at " + at;
    else
      status.data = std::string("completed at ") + at;
    if (end_at_)
      failure_.emplace(ExitCode::kNoTraction, "the run ended on no traction: " + status.data);
    else if (short_of_field)
      failure_.emplace(ExitCode::kStoppedShort, "the run stopped short of its field: " + status.data);
    if (failure_) logFailure(pnh_.getNamespace(), *failure_);
  }
  status_pub_.publish(status);
  std::printf("%s", core::metricsTable({label_}, {m}).c_str());
  std::fflush(stdout);
  if (!output_.empty() && !core::writeMetricsYaml(output_, label_, m))
    ROS_ERROR("run_monitor: could not write %s", output_.c_str());
  if (!exit_at_end_) return;
  if (recorder_topic_.empty()) {
    endRun();
    return;
  }
  // The recorder may be seconds of simulated time behind the loop (its queues hold them); the launch
  // must not end before it has them, or they die with their publishers.
  std::lock_guard<std::mutex> lock(wait_mutex_);
  if (recorded_until_ >= last_) {
    endRun();
    return;
  }
  ROS_INFO("run_monitor: waiting (up to %.0f s) for the recorder to write up to t = %.3f s (it has %.3f s)",
           recorder_timeout_, last_.toSec(), recorded_until_.toSec());
  waiting_ = true;
  waiter_ = std::thread([this] { waitForRecorder(); });
}

void RunMonitor::recordedCallback(const std_msgs::Time::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(wait_mutex_);
  recorded_until_ = msg->data;
  if (waiting_ && recorded_until_ >= last_) recorded_.notify_all();
}

void RunMonitor::waitForRecorder() {
  const ros::WallTime start = ros::WallTime::now();
  std::unique_lock<std::mutex> lock(wait_mutex_);
  const bool caught_up = recorded_.wait_for(lock, std::chrono::duration<double>(recorder_timeout_),
                                            [this] { return stop_ || recorded_until_ >= last_; });
  waiting_ = false;
  if (stop_) return;
  if (caught_up) {
    ROS_INFO("run_monitor: the recorder has the whole run (waited %.2f s)", (ros::WallTime::now() - start).toSec());
  } else {
    char text[256];
    std::snprintf(text, sizeof text,
                  "the recorder (%s) wrote the run only up to t = %.3f s of %.3f s within %.1f s wall "
                  "(recorder_timeout): the bag lacks the end of the run",
                  recorder_topic_.c_str(), recorded_until_.toSec(), last_.toSec(), recorder_timeout_);
    failure_.emplace(ExitCode::kGaveUp, text);
    logFailure(pnh_.getNamespace(), *failure_);  // the run's last word; the main exits with its code
  }
  endRun();
}

int RunMonitor::exitCode() const {
  std::lock_guard<std::mutex> lock(wait_mutex_);
  return failure_ ? failure_->exitCode() : 0;
}

RunMonitor::~RunMonitor() {
  {
    std::lock_guard<std::mutex> lock(wait_mutex_);
    stop_ = true;
  }
  recorded_.notify_all();
  if (waiter_.joinable()) waiter_.join();
}

void RunMonitor::endRun() {
  if (exit_at_end_) ros::requestShutdown();  // safe from any thread (as a nodelet: the shared callback thread)
}

}  // namespace sowing_robot
