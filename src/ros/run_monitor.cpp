#include "sowing_robot/ros/run_monitor.h"

#include <cstdio>

#include "sowing_robot/core/validation.h"
#include "sowing_robot/ros/component_params.h"
#include "sowing_robot/ros/msg_checks.h"

namespace sowing_robot {

RunMonitor::RunMonitor(ros::NodeHandle nh, ros::NodeHandle pnh) {
  ParamReader p(pnh);
  const core::RunSettings run = loadRunSettings(nh, p);
  core::RunMonitorSettings settings;
  loadTable(p, core::RunMonitorSettings::table(), settings);
  requireValid(p, core::firstError({settings.validate(), core::checkPositive("run/duration", run.duration, "s")}));
  duration_ = run.duration;
  output_ = settings.output;
  label_ = settings.label;
  exit_at_end_ = settings.exit_at_end;
  // The time-domain figures (rise, settling, overshoot) need every sample: 32 B per period, ~115 MB per
  // hour at 1 kHz. Long runs (soak) switch them off and keep only the integrals (constant memory).
  metrics_ = core::MetricsAccumulator(settings.time_domain);
  metrics_.reserve(static_cast<std::size_t>(duration_ * 1000.0) + 2);
  sub_ = nh.subscribe("tracking_error", kLockstepQueue, &RunMonitor::errorCallback, this, ros::TransportHints().tcpNoDelay());
}

void RunMonitor::errorCallback(const TrackingError::ConstPtr& msg) {
  if (done_) return;
  if (metrics_.samples() > 0 && msg->header.stamp <= last_) return;  // repeats answer a retried state
  if (!metrics_.add(msg->header.stamp.toSec(), msg->x, msg->y, msg->theta)) {  // refuses non-finite errors
    ROS_WARN_THROTTLE(1.0, "run_monitor: non-finite tracking error ignored");
    return;
  }
  last_ = msg->header.stamp;
  if (msg->header.stamp.toSec() >= duration_ - 1e-9) finish();
}

void RunMonitor::finish() {
  done_ = true;
  const auto m = metrics_.result();
  const std::string table = core::metricsTable({label_}, {m});
  ROS_INFO("run_monitor: %zu samples up to t = %.3f s\n%s", metrics_.samples(), last_.toSec(), table.c_str());
  std::printf("%s", table.c_str());
  std::fflush(stdout);
  if (!output_.empty() && !core::writeMetricsYaml(output_, label_, m))
    ROS_ERROR("run_monitor: could not write %s", output_.c_str());
  if (exit_at_end_) ros::requestShutdown();  // safe from any thread (as a nodelet: the shared callback thread)
}

}  // namespace sowing_robot
