// A field run in-process, measured on the body: the closed loop (closed_loop.h) on the field's reference (a
// FieldReference, or with field/follower path a FieldPathReference), with the footprint checked against the
// obstacles (ContactMonitor), the seed drill scoring the tool
// point, and the peaks of the robot's yaw rate and lateral acceleration v omega. Used by the avoidance
// tests and by run_scenario --field (the figures of the README's field table).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sowing_robot/core/model/contact.h"
#include "sowing_robot/core/model/footprint.h"
#include "sowing_robot/core/model/soil_map.h"
#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/seeding.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {
namespace core {

/// The footprint of urdf/sowing_robot.urdf (what footprintFromUrdf returns for it, as a polygon): the
/// chassis box x in [-0.26, 0.36], |y| <= 0.19 and the wheels' outer faces |y| = 0.265 over |x| <= 0.095.
/// For core tests and tools without urdfdom; the nodes read the URDF itself.
Footprint sowingRobotFootprint();

struct FieldRunSetup {
  Scenario scenario;  ///< duration, rate, start, disturbance, gains
  /// Rows, potential and avoidance parameters; an unset field.start_pose is taken from scenario.start
  /// (so with field.approach the target starts at the robot).
  FieldParams field;
  std::vector<Obstacle> obstacles;
  Footprint footprint = sowingRobotFootprint();
  Eigen::Vector2d tool{-0.45, 0.0};  ///< seed-drop point in base_link (the URDF's tool_link) [m]
  SeedingParams seeding;             ///< (detour_margin as config/seed_drill.yaml: 4 m)
  /// Obstacles the seed drill scores against when not empty (e.g. with one added at run time); else `obstacles`.
  std::vector<Obstacle> scoring_obstacles;
  /// Called every period after the reference of time t was taken (e.g. to change the obstacles).
  std::function<void(double t, FieldSource& reference, ContactMonitor& contacts)> on_step;
  /// Peaks are taken from this time on (e.g. after the approach from the start) [s].
  double peaks_from = 0.0;
  /// Set: the traction plant (traction.h) in place of the no-slip Plant, on these soil patches, with the tool's draft
  /// (traction->draft_force) while the tool is down by the plant's own rule (tool_engagement.h, on the
  /// field's rows), as plant_sim does with traction:=true.
  std::optional<TractionParams> traction;
  std::vector<SoilPatch> patches;
  FieldRunSetup();
};

struct FieldRunReport {
  double min_clearance = 0.0;  ///< body, over the run [m]
  std::size_t contacts = 0;
  std::vector<ContactEvent> events;
  double peak_yaw_rate = 0.0;                              ///< robot |omega| after peaks_from [rad/s]
  double peak_lateral = 0.0;                               ///< robot |v omega| after peaks_from [m/s^2]
  double peak_ref_yaw_rate = 0.0, peak_ref_lateral = 0.0;  ///< the same of the reference
  double peak_ref_curvature = 0.0;                         ///< |omega| / v of the reference where v > 0.05 m/s [1/m]
  double max_speed = 0.0;                                  ///< robot [m/s]
  SeedStats rows, detours;
  Eigen::Vector2d end = Eigen::Vector2d::Zero();  ///< final axle position [m]
  AvoidanceStatus status;
  bool diverged = false;
  long saturated = 0;           ///< control periods the inner loop saturated
  double max_slip = 0.0;        ///< with traction: largest |slip ratio| of either wheel
  double tool_down_time = 0.0;  ///< with traction and a draft: time the tool was down (the draft acting) [s]
  std::string summary() const;  ///< one line with every figure (the no-slip ones)
};

/// Throws std::invalid_argument on invalid parameters.
FieldRunReport runField(const FieldRunSetup& setup);

/// How much longer the field's reference runs than its path without the approach from the start pose [s]: the
/// approach, and with field/follower path the follower's own timing (0 for neither). A run of fixed duration
/// lengthened by this ends at the same point of the rows.
double approachExtraTime(const FieldRunSetup& setup);
/// The same for a reference already built (its params() carry the start pose).
double approachExtraTime(const FieldSource& reference);

}  // namespace core
}  // namespace sowing_robot
