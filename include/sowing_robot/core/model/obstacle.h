// A circular obstacle of the field: what the contact monitor checks the body against and what the
// planners (potential field, detours) steer around.
#pragma once

#include <string>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

/// Circular obstacle.
struct Obstacle {
  double x = 0.0, y = 0.0;  ///< centre [m]
  double radius = 0.3;      ///< [m], > 0

  /// "" or one line naming the bad value.
  std::string validate() const {
    if (!allFinite(x, y))
      return "obstacle centre (" + std::to_string(x) + ", " + std::to_string(y) + ") must be finite";
    return checkPositive("radius", radius, "m");
  }
};

}  // namespace core
}  // namespace sowing_robot
