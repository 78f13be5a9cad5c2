// reference_generator's type path (core/planning/path_plan.h), and type field with field/follower path (the
// field's rows and turns as a path, core/planning/field_path_follower.h): where the path comes from, and what is
// reported of following it. The references themselves are sent by reference_generator, like any other.
//   ~path/points ([[x, y], ...] in the odom frame [m]): the path at start-up (sim.launch path_file:= loads it).
//   path (nav_msgs/Path, latched or not): replaces the path in force from the reference last sent, so it applies
//     to the references not yet sent (`lookahead` later). The poses' positions are used; a path in another
//     frame than odom, with a non-finite position or none at all is dropped with a warning.
//   feedback (nav_msgs/Odometry, what the controllers are fed): the robot's progress along the path:
//     ~progress (PathProgress, latched; every 0.1 s of simulated time and on each change of status), and the
//     end-of-path report in the log, once per path, when the robot is within path/goal_tolerance of the goal.
//   planned_path (nav_msgs/Path, latched): the drivable path (corners rounded, every 5 cm, at most 20000
//     poses: a longer path, a whole field's route, more sparsely) for rviz.
// The progress never feeds back into the references: in lockstep they stay a function of time and of the
// paths received.
#pragma once

#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "sowing_robot/PathProgress.h"
#include "sowing_robot/core/planning/path_plan.h"
#include "sowing_robot/ros/common/param_reader.h"

namespace sowing_robot {

/// Reads ~path/points (absent: no path, ""); returns "" or one line naming what is wrong. Marks the key read.
std::string loadPathPoints(ParamReader& p, std::vector<Eigen::Vector2d>& out);

class PathFollower {
 public:
  /// `source` is reference_generator's (it outlives this object); frame: run/odom_frame; origin: where the path
  /// given at start-up comes from (the log line's "path 1 from ...").
  PathFollower(ros::NodeHandle nh, ros::NodeHandle pnh, core::PathReference& source, std::string frame,
               const char* origin = "path/points");
  /// The owner replaced the path in force (the field re-planned round new obstacles): report it as a new path.
  void replaced(const char* why) { planChanged(why); }
  /// reference_generator has sent the reference stamped stamp_ns: the path source's time then (with the speed
  /// governor it runs slower than the clock) and the path in force, against which the state of that stamp is
  /// measured.
  void referenceSent(std::int64_t stamp_ns);

 private:
  struct Sent {
    std::int64_t stamp_ns;
    double source_time;  ///< [s] the path source's time of that reference
    std::uint32_t path;  ///< the path in force (progress_.path)
  };
  void pathCallback(const nav_msgs::Path::ConstPtr& msg);
  void feedbackCallback(const nav_msgs::Odometry::ConstPtr& msg);
  /// A new plan is in force: its planned_path, the log line, and the progress reset.
  void planChanged(const char* why);
  void publishProgress(const ros::Time& stamp);

  core::PathReference& source_;
  std::string frame_;
  ros::Subscriber path_sub_, feedback_sub_;
  ros::Publisher progress_pub_, planned_pub_;
  PathProgress progress_;      ///< the last one published (its path count and statistics)
  double s_robot_ = 0.0;       ///< the robot's arc length at the last feedback [m]
  double sum_sq_ = 0.0;        ///< of cross_track on this path [m^2]
  std::uint64_t samples_ = 0;  ///< feedback messages on this path
  double next_publish_ = 0.0;  ///< [s] simulated time of the next periodic ~progress
  std::deque<Sent> sent_;      ///< references sent whose states have not come yet (bounded)
};

}  // namespace sowing_robot
