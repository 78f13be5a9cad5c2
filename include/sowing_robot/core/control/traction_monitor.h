// No traction: the progress check of the traction control layer. A robot on a patch where no
// grip is to be had (the drive wheels' peak traction below rolling resistance + draft) spins its wheels
// and gets nowhere; driving on, it would spin, orbit or wander. As nav2's progress checker and the
// immobilisation detectors of planetary rovers (FIELD.md), the verdict comes from what the robot measures:
// the traction control's slip verdict (encoder wheel speed against the ground speed) and the fed pose (the
// estimate, never the hidden truth):
//   while the plan drives (no stop hold), the window runs from the last pose at which the robot had made
//   `no_traction_progress` of ground progress; once it has run `no_traction_window` with the wheels
//   slipping for at least `no_traction_slip_share` of it, the verdict is "no traction" (latched).
// The caller then stops the robot (a stop hold) and ends the run with the report. Parameters: the traction
// control's table (traction_control.h), inert unless the traction control is on.
#pragma once

#include <string>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/control/traction_control.h"

namespace sowing_robot {
namespace core {

/// Where and why the robot was found without traction.
struct NoTractionReport {
  bool detected = false;
  double t = 0.0;         ///< time of the verdict [s]
  Pose2D where;           ///< the fed pose at the verdict
  double slip = 0.0;      ///< time the wheels slipped within the window [s]
  double span = 0.0;      ///< the window: time since the last progress [s]
  double progress = 0.0;  ///< ground progress over the window [m]
  std::string diagnosis;  ///< what the caller knows beyond the measurements (a simulation: the soil's grip budget)
  /// "no traction at (x y): ..." on one line without commas (a CSV field), the diagnosis after "; ".
  std::string text() const;
};

class TractionMonitor {
 public:
  /// The no_traction_* keys of `params` (validated by TractionControlParams::validate()).
  explicit TractionMonitor(const TractionControlParams& params);
  void reset();
  /// One period: time t [s], the fed pose, whether the plan drives (false at a stop hold: the check
  /// rests), the traction control's slip verdict, the period dt [s]. Returns the verdict (latched).
  bool update(double t, const Pose2D& fed, bool driving, bool slipping, double dt);
  bool detected() const { return report_.detected; }
  const NoTractionReport& report() const { return report_; }
  /// False when no_traction_window is 0 (the check off).
  bool active() const { return window_ > 0.0; }

 private:
  double window_, progress_, share_;
  bool anchored_ = false;
  Pose2D anchor_;
  double t0_ = 0.0, slip_ = 0.0;
  NoTractionReport report_;
};

}  // namespace core
}  // namespace sowing_robot
