#include "sowing_robot/core/model/robot_params.h"

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

std::string RobotParams::validate() const {
  return firstError({checkPositive("mc", mc, "kg"), checkNonNegative("mw", mw, "kg"),
                     checkRange("d", d, -1.0, 1.0, "m"), checkPositive("L", L, "m"), checkPositive("R", R, "m"),
                     checkPositive("Ic", Ic, "kg·m^2"), checkNonNegative("Im", Im, "kg·m^2"),
                     checkNonNegative("Iw", Iw, "kg·m^2")});
}

}  // namespace core
}  // namespace sowing_robot
