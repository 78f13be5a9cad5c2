// run_monitor: accumulates the tracking-error metrics of a run (Tables 5.5/5.6) and prints them when
// the scenario ends. The errors are the TRUE ones: ground_truth against the reference of the same stamp
// (core::worldErrors, as kinematic_controller computes its tracking_error from its feedback, so with
// feedback:=ground_truth the numbers are the same bit for bit), whatever the controllers are fed;
// optionally writes them to YAML and ends the launch (headless runs). With a recorder
// (`~recorder`: its recorded_until topic) it ends the launch only once the recorder has written the
// run's last period, or, after `~recorder_timeout` wall seconds without that, with a failure (exit 3).
// With torque_controller's traction control on, its `traction_control/state` may bring the no-traction verdict
// (core/control/traction_monitor.h): the run then ends no_traction_hold after it, with the report, as the
// in-process loop ends it. In lockstep a period is scored only once the traction state of its stamp is in, so the
// end falls on the same period whatever the messages' timing.
// `~status` (std_msgs/String, latched) says once how the run ended: "completed at t = T s" or "no traction at
// (x y): ...; ended at t = T s".
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <std_msgs/Time.h>

#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "sowing_robot/FieldPlan.h"
#include "sowing_robot/ReferenceState.h"
#include "sowing_robot/TractionControlState.h"
#include "sowing_robot/core/simulation/metrics.h"
#include "sowing_robot/ros/common/node_failure.h"
#include "sowing_robot/ros/common/ready_roster.h"
#include "sowing_robot/ros/common/stamp_pair.h"

namespace sowing_robot {

class RunMonitor {
 public:
  RunMonitor(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~RunMonitor();

  /// The exit code the run ended with: 0, or kGaveUp when the recorder never confirmed the end.
  int exitCode() const;

 private:
  void truthCallback(const nav_msgs::Odometry::ConstPtr& msg);
  void referenceCallback(const ReferenceState::ConstPtr& msg);
  /// The true error of the state and reference paired for one stamp (scored now, or held until the traction
  /// state of its stamp is in).
  void addPair();
  void score(const ros::Time& stamp, double ex, double ey, double eth);
  void tractionCallback(const TractionControlState::ConstPtr& msg);
  /// Scores the held periods up to the last traction state's stamp.
  void flush();
  void recordedCallback(const std_msgs::Time::ConstPtr& msg);
  void waitForRecorder();
  void finish();
  void endRun();

  double duration_ = 25.0;
  double recorder_timeout_ = 60.0;  // [s wall] for the recorder to catch up after the last period
  std::string output_, label_, recorder_topic_;
  bool exit_at_end_ = false, done_ = false;
  core::MetricsAccumulator metrics_;
  ros::Time last_;
  ros::NodeHandle pnh_;
  // The reference is sent ahead of the state, but the plant does not wait for this node: under load its
  // states can arrive seconds ahead of their references, so both streams hold a whole lookahead's worth.
  ListenerPair<nav_msgs::Odometry, ReferenceState> inputs_;
  std::int64_t expected_samples_ = 0;  // lockstep: every period of the run, both ends included (0: not checked)
  ros::Subscriber truth_sub_, ref_sub_, recorder_sub_, traction_sub_;
  ros::Publisher status_pub_;              ///< ~status
  ros::Subscriber plan_sub_;               ///< the reference generator's plan: whether it stops short of the field
  std::string plan_status_, plan_reason_;  ///< the last plan's status (ok | stopped_short | no_safe_way) and reason
  void planCallback(const FieldPlan::ConstPtr& msg);
  // No traction (torque_controller's traction control on).
  struct Held {
    ros::Time stamp;
    double ex, ey, eth;
  };
  std::deque<Held> held_;          ///< lockstep: periods waiting for their traction state
  bool gated_ = false;             ///< lockstep with traction control: periods wait for their traction state
  ros::Time traction_until_;       ///< the latest traction state's stamp
  double no_traction_hold_ = 3.0;  ///< torque_controller/traction_control/no_traction_hold [s]
  std::optional<double> end_at_;   ///< the verdict came: the run ends at this time [s]
  std::string no_traction_;        ///< its report

  // The wait for the recorder: a thread of its own with a bounded wait, not a ros::WallTimer: roscpp's
  // timer thread queues a callback while holding its timer lock, and InlineCallbackQueue runs it right
  // there, where re-scheduling the timer takes that lock again (a deadlock, seen).
  mutable std::mutex wait_mutex_;
  std::condition_variable recorded_;
  ros::Time recorded_until_;             // under wait_mutex_
  bool waiting_ = false, stop_ = false;  // under wait_mutex_
  std::optional<NodeFailure> failure_;   // under wait_mutex_
  std::thread waiter_;
  ReadyAnnouncer ready_;  // plant_sim waits for it before step 0
};

}  // namespace sowing_robot
