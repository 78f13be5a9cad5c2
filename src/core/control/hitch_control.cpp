#include "sowing_robot/core/control/hitch_control.h"

#include <cmath>
#include <stdexcept>

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
  });
  return table;
}

HitchControlParams::HitchControlParams() { hitchControlTable().applyDefaults(*this); }

std::string HitchControlParams::validate() const { return hitchControlTable().checkRanges(*this); }

HitchControl::HitchControl(const HitchControlParams& params) : params_(params) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
}

void HitchControl::reset() {
  raised_ = false;
  raises_ = 0;
  limited_for_ = gripped_for_ = 0.0;
}

bool HitchControl::update(bool grip_limited, double travelled, double dt) {
  if (!params_.enabled) return false;
  if (grip_limited) {
    limited_for_ += dt;
    gripped_for_ = 0.0;
    if (!raised_ && limited_for_ >= params_.raise_after) {
      raised_ = true;
      ++raises_;
    }
  } else {
    limited_for_ = 0.0;
    if (std::isfinite(travelled) && travelled > 0.0) gripped_for_ += travelled;
    if (raised_ && gripped_for_ >= params_.lower_after) raised_ = false;
  }
  return raised_;
}

}  // namespace core
}  // namespace sowing_robot
