// reference_generator: publishes the reference posture, velocities and accelerations on the control
// grid (t_k = k / control_rate, the stamps of the plant's states), plus the reference path for rviz.
// The reference depends on time (and the obstacle list) only, so it is sent ahead: paced by /clock,
// every reference up to `lookahead` seconds after it. The loop then never waits for this node, which
// gets no message per step (/clock comes at plant_sim's clock_rate); an obstacle or gain change takes
// effect on references not yet sent, i.e. `lookahead` later.
//   type line:  core::LineReference (the thesis's sowing line).
//   type field: core::FieldReference (rows + headland turns through the potential field) with the
//               obstacles from the `obstacles` parameter; `obstacles` (MarkerArray) replaces them at
//               run time, and `field_markers` (latched) shows obstacles, influence zones and rows.
//               With field/follower path: core::FieldPathReference, the field's rows and turns as a path
//               through the follower of type path (core/planning/field_path_follower.h), with its reports.
//   type coverage: the field of a field file (field_file, docs/field_file.md) planned by the coverage planner
//               (coverage/..., core/planning/coverage_planner.h) and its route (ros/coverage_route.h: from the
//               route's own start, where plant_sim places the robot; with fleet/robots, this robot's share after
//               its planned wait, core/planning/fleet_share.h) followed by the path follower
//               (coverageFollowerParams, core/planning/coverage_follower.h); the plan on coverage/...
//               (ros/coverage_topics.h); on `plan` for the seed drill the swaths' and headland rows (a fleet
//               robot: its own swaths' rows).
//   type path:  core::PathReference (a given path, rounded and timed: core/planning/path_plan.h), from
//               path/points or nav_msgs/Path on `path`; ros/path_follower.h says what it reports.
// Speed governor (speed_governor/..., core/planning/speed_governor.h; off by default): the source's time runs
// at a rate that falls while the torque controller's traction control reports slip (`traction_control/state`)
// and rises while the wheels grip. The reference for t_{k+1} then depends on the verdict of period k, so in
// lockstep it is sent only once that verdict is in: the window ends one period after the last verdict (the
// in-process loop's order, closed_loop.h). In realtime the verdicts are applied as they come, to the
// references not yet sent.
// A fleet sharing a field (type coverage, fleet/robots > 0; ros/coverage_route.h): this robot's share of the split
// plan, standing at its start for its planned wait (core::FleetShareReference). With fleet/yield the fleet decides at
// run time who holds: on every decision stamp t (a multiple of fleet/decision_period) this node publishes its state at
// t (fleet/status: ground_truth's position at t, its progress) and sends no reference past t until fleet_monitor's
// verdict for t has come (/fleet/verdict), which then holds or releases the references after t. Every robot's
// references thus depend on every robot's states at the decision stamps only, whatever the loops' relative pace.
#pragma once

#include <dynamic_reconfigure/server.h>

#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <visualization_msgs/MarkerArray.h>
#include "sowing_robot/ros/common/reconfigure_bridge.h"

#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "sowing_robot/FieldPlan.h"
#include "sowing_robot/FleetRobotStatus.h"
#include "sowing_robot/FleetVerdict.h"
#include "sowing_robot/ReferenceGeneratorConfig.h"
#include "sowing_robot/ReferenceState.h"
#include "sowing_robot/TractionControlState.h"
#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/fleet_share.h"
#include "sowing_robot/core/planning/speed_governor.h"
#include "sowing_robot/ros/common/path_buffer.h"
#include "sowing_robot/ros/common/ready_roster.h"
#include "sowing_robot/ros/coverage_route.h"
#include "sowing_robot/ros/coverage_topics.h"
#include "sowing_robot/ros/path_follower.h"

namespace sowing_robot {

class ReferenceGenerator {
 public:
  ReferenceGenerator(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  /// Sends every reference up to the new simulated time + the window.
  void clockCallback(const rosgraph_msgs::Clock::ConstPtr& msg);
  /// Sends the references from next_ns_ up to `end` [ns] (lockstep with the governor: up to one period after
  /// the last verdict).
  void sendUpTo(std::int64_t end);
  /// The governor: the traction control's verdict of one period, for the references after it.
  void tractionCallback(const TractionControlState::ConstPtr& msg);
  /// fleet/yield: the fleet's verdict for one decision stamp, for the references after it.
  void verdictCallback(const FleetVerdict::ConstPtr& msg);
  /// fleet/yield: the robot's true position on a decision stamp (for its fleet/status).
  void truthCallback(const nav_msgs::Odometry::ConstPtr& msg);
  /// fleet/status for the decision stamp once both its reference and its true state are in.
  void publishStatus();
  /// A late subscriber gets the references already sent for times still ahead.
  void replayTo(const ros::SingleSubscriberPublisher& sub);
  /// The source's reference at stamp into out.
  void fill(ReferenceState& out, const ros::Time& stamp);
  /// type field: every ADD CYLINDER marker is an obstacle (centre = pose.position, radius = scale.x / 2);
  /// the message replaces the whole list. A message with a non-finite or non-positive value is dropped.
  void obstaclesCallback(const visualization_msgs::MarkerArray::ConstPtr& msg);
  /// The plan in force (rows, obstacles, influence) on `plan`, latched; type field: field_markers too.
  void publishPlan();
  /// type field: the plan's status in the log (a stop short of a target, no safe way, bounds not held).
  void reportStatus();
  /// type field: obstacles, influence zones (field/follower potential) and row lines on field_markers.
  void publishMarkers();
  /// type field: live avoidance gains, validated like the start-up values (a rejected change keeps them).
  void reconfigure(ReferenceGeneratorConfig& config, uint32_t level);

  std::unique_ptr<core::ReferenceSource> source_;  ///< the reference sent (governed, with the governor)
  core::GovernedReference* governor_ = nullptr;    ///< source_ when the speed governor is on, else null
  bool lockstep_ = false;                          ///< run/mode
  std::int64_t verdict_ns_ = -1;                   ///< stamp of the last traction-control verdict [ns]; -1: none
  core::FieldSource* field_ = nullptr;             ///< source_ when type is field, else null
  core::FieldReference* potential_ = nullptr;      ///< field_ with field/follower potential, else null
  std::vector<core::Obstacle> obstacles_;          ///< the obstacles in force (type field)
  std::unique_ptr<PathFollower> path_follower_;    ///< type path, field/follower path: inputs, progress; else null

  // a fleet's robot (type coverage, fleet/robots > 0), else null / unset
  core::FleetShareReference* fleet_ = nullptr;  ///< its share's reference (inside source_)
  int fleet_index_ = 0, fleet_rank_ = 0;
  bool yield_ = false;                  ///< fleet/yield
  std::int64_t decision_ns_ = 0;        ///< fleet/decision_period [ns]
  std::int64_t fleet_verdict_ns_ = -1;  ///< stamp of the last verdict [ns]; -1: none
  std::int64_t status_ns_ = -1;         ///< the decision stamp whose status is being gathered
  bool status_ref_ = false, status_truth_ = false;
  FleetRobotStatus status_;
  ros::Subscriber verdict_sub_, truth_sub_;
  ros::Publisher status_pub_;

  // type coverage, else null / empty
  std::unique_ptr<CoverageTopics> coverage_topics_;  ///< the plan on coverage/...
  std::vector<core::RowSegment> coverage_rows_;      ///< the plan's tool rows (sent on `plan`)

  ros::Subscriber clock_sub_, obstacles_sub_, traction_sub_;
  ros::Publisher ref_pub_, path_pub_, marker_pub_, plan_pub_;
  std::string odom_frame_ = "odom";    ///< run/odom_frame
  Eigen::Vector2d line_{0.0, 3.0};     ///< type line: (x0, y), where the open-ended row starts
  std::deque<ReferenceState> sent_;    ///< published, for times not yet passed (replayed to late subscribers)
  double lookahead_ = 0.05;            ///< [s] send references this far ahead of /clock
  std::int64_t window_ns_ = 50000000;  ///< [ns] lookahead, or twice the largest /clock gap seen if longer
  std::int64_t next_ns_ = -1;          ///< stamp of the next reference to send [ns]
  std::int64_t last_clock_ns_ = 0;
  bool clock_seen_ = false, grid_warned_ = false;
  std::int64_t period_ns_ = 1000000;  ///< control period (control_rate) [ns]
  std::unique_ptr<PathBuffer> path_;  // reference_path (spacing from the parameters)
  double path_spacing_ = 0.1;         // [m] between stored reference path points
  std::unique_ptr<ReconfigureServer<ReferenceGeneratorConfig>> reconfigure_;  // field/follower potential only
  ReadyAnnouncer ready_;                                                      // plant_sim waits for it before step 0
};

}  // namespace sowing_robot
