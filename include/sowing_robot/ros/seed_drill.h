// seed_drill: the plant-side seed drill. Follows the tool point (URDF `tool_link`) on odom, drops a seed
// every `spacing` metres while the tool is down (the reference's tool_down for the same stamp, unless
// torque_controller's hitch control holds it up for that stamp: ~follow_hitch), shows
// the seeds in rviz and reports the cross-track error of the sown line against the intended rows (away
// from obstacles and in detours apart).
// Outputs: `seeds` (visualization_msgs/MarkerArray, a chunk of points per message, stamped with the state's
// stamp) and `seed_report` (std_msgs/Float64MultiArray, latched, at the plan, every 50 seeds and once
// more for the run's final state (run/duration > 0: the last state of the run on the control period's grid),
// so that the last report holds every seed of the run; its label names the entries: rows_count, rows_max,
// rows_rms, rows_fraction_over, detour_count, detour_max, detour_rms [m], stamp [s, of the state that sowed
// the last seed; of the final state in the final report]). A tester waits for the report stamped at the
// run's end instead of guessing when the drill has caught up (the plant does not wait for this node).
// And `seeds/record` (sowing_robot/Seed, one message per seed, stamped with the state it fell at, in the odom
// frame): where it fell (the tool point on ground_truth), where the robot believed its tool was (the tool point
// on `feedback`, the pose the controllers are fed, paired with the true state by stamp), its row, depth and
// detour flag: the run's seed record, which bags keep and `seed_map` exports (docs/seed_map.md). Without a
// remapping of `feedback` (a launch whose controllers read ground_truth) the believed position is the true one.
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <visualization_msgs/Marker.h>

#include <memory>

#include "sowing_robot/FieldPlan.h"
#include "sowing_robot/ReferenceState.h"
#include "sowing_robot/Seed.h"
#include "sowing_robot/WheelTorque.h"
#include "sowing_robot/core/planning/seeding.h"
#include "sowing_robot/core/settings/node_settings.h"
#include "sowing_robot/ros/common/ready_roster.h"
#include "sowing_robot/ros/common/stamp_pair.h"

namespace sowing_robot {

/// What the plan and the hitch say of the tool for one stamp.
struct ToolState {
  bool down = false;     ///< the reference asks for the tool (ReferenceState/tool_down)
  bool held_up = false;  ///< the hitch holds it up (WheelTorque/tool_raised)
  double depth = 0.0;    ///< the depth the drill runs at [m] (seedDepth)
};

class SeedDrillNode {
 public:
  SeedDrillNode(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~SeedDrillNode();

 private:
  void odomCallback(const nav_msgs::Odometry::ConstPtr& msg);
  void referenceCallback(const ReferenceState::ConstPtr& msg);
  /// The hitch command of a stamp (~follow_hitch): comes after that stamp's state (the loop answers it).
  void torqueCallback(const WheelTorque::ConstPtr& msg);
  /// The state and the reference's tool_down of one stamp: sown from now, or once its hitch command is here.
  void paired(const nav_msgs::Odometry& odom, bool tool_down);
  /// hitch_inputs_ has just paired a stamp: the tool is down where the reference sows and the hitch left it.
  void updateHitchPair();
  /// The reference generator's plan: the first one starts the drill, later ones replace its rows and
  /// obstacles (run-time obstacle changes).
  void planCallback(const FieldPlan::ConstPtr& msg);
  /// The state and whether the tool is down for the same time: sown now, or once the believed pose of
  /// its stamp is here (`feedback` other than ground_truth).
  void update(const nav_msgs::Odometry& odom, const ToolState& tool);
  /// The pose the controllers are fed (`feedback`), when it is not ground_truth itself.
  void believedCallback(const nav_msgs::Odometry::ConstPtr& msg);
  /// The true and the believed state of one stamp: move the tool, maybe drop a seed; the final report after
  /// the run's final state.
  void sow(const nav_msgs::Odometry& truth, const nav_msgs::Odometry& believed, const ToolState& tool);
  /// The tool point (odom frame) on a state's pose.
  Eigen::Vector2d toolPoint(const nav_msgs::Odometry& odom) const;
  /// The depth a seed is placed at [m], the one place it comes from: the depth control's, sent with the wheel
  /// torque (WheelTorque/tool_depth, follow_hitch), or without one the drill's nominal, the middle of the
  /// agronomic band (seed_drill/depth_min..depth_max, as the in-process SeedRecorder).
  double seedDepth(double sent_depth) const;
  /// A seed dropped by the state stamped `stamp`: recorded, shown, and every 50th reported.
  void addSeed(const core::Seed& seed, const ros::Time& stamp);
  void publishReport(const ros::Time& stamp);

  core::SeedDrillSettings settings_;
  std::unique_ptr<core::SeedDrill> drill_;  ///< null until the first plan
  double tool_x_ = 0.0, tool_y_ = 0.0;      // tool point in base_link [m]
  // The reference is sent ahead of the state, but the plant does not wait for this node: its states can
  // arrive far ahead of their references, so both streams hold a whole lookahead's worth (stamp_pair.h).
  ListenerPair<nav_msgs::Odometry, ReferenceState> inputs_;
  struct Paired {  // what inputs_ paired, waiting for the hitch command of its stamp
    std_msgs::Header header;
    nav_msgs::Odometry odom;
    bool tool_down = false;
  };
  ListenerPair<Paired, WheelTorque> hitch_inputs_;
  // What is to be sown (the true state and the tool), waiting for the believed pose of its stamp. That comes
  // from another connection or process (the estimator) at its own pace: both sides hold a whole lookahead.
  struct Sowing {
    std_msgs::Header header;
    nav_msgs::Odometry truth;
    ToolState tool;
  };
  ListenerPair<Sowing, nav_msgs::Odometry> believed_inputs_;
  bool believed_is_truth_ = true;  ///< `feedback` is ground_truth (or not remapped): no second subscription
  ros::Subscriber plan_sub_, odom_sub_, ref_sub_, torque_sub_, believed_sub_;
  ros::Publisher seeds_pub_, record_pub_, report_pub_;
  std::string odom_frame_;
  visualization_msgs::Marker chunk_;  // the current SPHERE_LIST of up to kChunk seeds
  int chunk_id_ = 0;
  std::size_t seeds_ = 0;
  std::int64_t end_ns_ = -1;  ///< stamp of the run's final state [ns]; -1: the run has no end (duration 0)
  bool final_sent_ = false;   ///< the final report is out
  ReadyAnnouncer ready_;      // plant_sim waits for it before step 0
};

}  // namespace sowing_robot
