#include "sowing_robot/core/control/hitch_control.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

const ParamTable<HitchControlParams>& hitchControlTable() {
  using P = HitchControlParams;
  static const ParamTable<P> table({
      flag("hitch_control/enabled", &P::enabled, false,
           "raise the seed drill's tool while the traction control holds the wheels at their grip limit (slip-limit "
           "hitch control); false: the tool follows the seed drill's rule alone"),
      number("hitch_control/raise_after", &P::raise_after, 0.0, Limits::closed(0.0, 10.0), "s",
             "the traction control's grip verdict must stand this long without a break before the tool is raised"),
      number("hitch_control/lower_after", &P::lower_after, 5.0, Limits::closed(0.0, 100.0), "m",
             "the robot's travel without the verdict before the tool is lowered again"),
      flag("hitch_control/depth_control", &P::depth_control, false,
           "depth (down-pressure) control: on the grip verdict run the seed drill shallower, within the agronomic "
           "band, and raise it only at depth_shallowest; false: raise it at once (raise_after)"),
      number("hitch_control/depth_nominal", &P::depth_nominal, 0.04, Limits::positive(), "m",
             "the drill's working depth while the wheels grip (as plant_sim/traction/draft_depth, the depth the "
             "draft is given for)"),
      number("hitch_control/depth_shallowest", &P::depth_shallowest, 0.03, Limits::positive(), "m",
             "the shallowest depth the depth control runs the drill at before it raises it (the agronomic band's "
             "shallowest, seed_drill/depth_min); <= depth_nominal"),
      number("hitch_control/depth_rate", &P::depth_rate, 0.02, Limits::above(0.0, 10.0), "m/s",
             "how fast the down-pressure changes the drill's depth (0.02: the 1 cm from 4 to 3 cm in 0.5 s)"),
      number("hitch_control/deepen_after", &P::deepen_after, 1.0, Limits::closed(0.0, 100.0), "m",
             "the robot's travel without the verdict before the drill goes back deeper (at depth_rate)"),
  });
  return table;
}

HitchControlParams::HitchControlParams() { hitchControlTable().applyDefaults(*this); }

std::string HitchControlParams::validate() const {
  const std::string e = hitchControlTable().checkRanges(*this);
  if (!e.empty()) return e;
  if (depth_shallowest > depth_nominal)
    return "hitch_control/depth_shallowest = " + formatNumber(depth_shallowest) +
           " must be <= hitch_control/depth_nominal = " + formatNumber(depth_nominal);
  return "";
}

HitchControl::HitchControl(const HitchControlParams& params) : params_(params), depth_(params.depth_nominal) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
}

void HitchControl::reset() {
  raised_ = false;
  raises_ = 0;
  limited_for_ = gripped_for_ = 0.0;
  depth_ = params_.depth_nominal;
}

bool HitchControl::update(bool grip_limited, double travelled, double dt) {
  if (!params_.enabled) return false;
  const bool depth = params_.depth_control;
  if (grip_limited) {
    gripped_for_ = 0.0;
    if (depth && !raised_ && depth_ > params_.depth_shallowest) {
      // Shallower first; the verdict's time toward raising counts only from a period begun at the shallowest.
      depth_ = std::max(params_.depth_shallowest, depth_ - params_.depth_rate * dt);
      limited_for_ = 0.0;
    } else {
      limited_for_ += dt;
      if (!raised_ && limited_for_ >= params_.raise_after) {
        raised_ = true;
        ++raises_;
      }
    }
  } else {
    limited_for_ = 0.0;
    if (std::isfinite(travelled) && travelled > 0.0) gripped_for_ += travelled;
    if (raised_ && gripped_for_ >= params_.lower_after) raised_ = false;
    if (depth && !raised_ && gripped_for_ >= params_.deepen_after)
      depth_ = std::min(params_.depth_nominal, depth_ + params_.depth_rate * dt);
  }
  return raised_;
}

}  // namespace core
}  // namespace sowing_robot
