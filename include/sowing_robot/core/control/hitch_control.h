// Slip-limit hitch control: the seed drill's tool is raised while the drive wheels are held at their grip
// limit and lowered again once they have gripped for a stretch, as a tractor's slip-limit control raises
// the hitch above a slip threshold (McCormick MTX; FIELD.md) so that the draft no longer takes the grip
// the drive needs. On the thesis wet patch this is what decides whether the robot can go round the
// obstacle: with the tool down the draft (10 N behind the axle) needs most of the peak grip to be
// pulled straight and, in the detour's turns, a yaw moment that the outer wheel cannot add at mu 0.2
// (docs/drive_train.md); with it up the rolling resistance alone leaves a wide margin.
//
// The trigger is the traction control's grip verdict (TractionControl::limiting(): a wheel's command cut
// to its ceiling, i.e. the inner loop asks for more than the soil carries), not a slip threshold of its
// own: the traction control holds the slip near the friction peak, so a tractor's 30 % threshold would
// never be reached while it works. Per period:
//   - held down and the verdict has stood for raise_after seconds without a break: raise;
//   - raised and the robot has travelled lower_after metres since the verdict last stood: lower.
// The robot's travel (|v| dt of the fed twist) rather than time decides the lowering, so a robot that
// stands still does not lower the tool into a patch it could not pull through. The rows the tool misses
// while raised are unsown: the closed loop counts that distance (LoopResult::unsown_distance);
// the seed drill keeps its spacing by distance, so the seeds after the stretch fall where they would.
//
// Depth control (depth_control): real drills set their depth with down-pressure and run shallower in wet
// ground, lifting only at the headland (FIELD.md). The draft grows with the depth (ASABE D497, traction.h's
// toolDraft), so a shallower drill leaves more of the grip to the drive. With depth_control the verdict
// first drives the drill shallower, within the agronomic band, and lifts it only as a last resort. Per period:
//   - the verdict stands and the tool is down: the depth falls at depth_rate toward depth_shallowest (the
//     band's shallowest, seed_drill/depth_min); there, once the verdict has stood raise_after seconds without
//     a break, the tool is raised (as without depth control, but only from the shallowest depth);
//   - raised: lowered after lower_after metres without the verdict, at the shallowest depth;
//   - down and the robot has travelled deepen_after metres without the verdict: the depth rises at
//     depth_rate back to depth_nominal (the drill's working depth, traction/draft_depth).
// The speed governor, which slows the target on the same grip verdicts, acts first through the loop's order
// (its verdict is the one of the period before). depth() is the working depth set, also while the tool is
// raised (the depth it comes down at); raised() says whether it is up.
#pragma once

#include <string>

#include "sowing_robot/core/common/param_table.h"

namespace sowing_robot {
namespace core {

/// Defaults, ranges, units and meanings: hitchControlTable().
struct HitchControlParams {
  HitchControlParams();
  bool enabled;             ///< false: the tool follows the seed drill's rule alone
  double raise_after;       ///< [s] the grip verdict must stand this long before the tool is raised
  double lower_after;       ///< [m] travel without the verdict before the tool is lowered again
  bool depth_control;       ///< run the drill shallower within the band before raising it
  double depth_nominal;     ///< [m] the drill's working depth with grip (as traction/draft_depth)
  double depth_shallowest;  ///< [m] the shallowest depth it runs at before it is raised (seed_drill/depth_min)
  double depth_rate;        ///< [m/s] how fast the down-pressure changes the depth
  double deepen_after;      ///< [m] travel without the verdict before the drill goes back deeper

  std::string validate() const;
};
/// hitch_control/{enabled, raise_after, lower_after, depth_control, depth_nominal, depth_shallowest, depth_rate,
/// deepen_after}.
const ParamTable<HitchControlParams>& hitchControlTable();

class HitchControl {
 public:
  /// Throws std::invalid_argument when the parameters do not validate.
  explicit HitchControl(const HitchControlParams& params);
  void reset();
  /// One period of dt [s]: grip_limited is the traction control's verdict of this period, travelled the
  /// distance the robot moved in it [m] (>= 0). Returns raised(). Disabled: never raises.
  bool update(bool grip_limited, double travelled, double dt);
  /// The tool is held up (whatever the seed drill's rule says).
  bool raised() const { return raised_; }
  /// The drill's working depth [m]: depth_nominal without depth control; with it, between depth_shallowest and
  /// depth_nominal (while raised: the depth the tool comes down at).
  double depth() const { return depth_; }
  /// Whether depth control is on (enabled and depth_control).
  bool controlsDepth() const { return params_.enabled && params_.depth_control; }
  /// Times the tool was raised since reset().
  int raises() const { return raises_; }
  const HitchControlParams& params() const { return params_; }

 private:
  HitchControlParams params_;
  bool raised_ = false;
  int raises_ = 0;
  double limited_for_ = 0.0;  // [s] the verdict has stood without a break
  double gripped_for_ = 0.0;  // [m] travelled since the verdict last stood
  double depth_;              // [m] see depth()
};

}  // namespace core
}  // namespace sowing_robot
