#include "sowing_robot/core/planning/field_soil.h"

#include <algorithm>
#include <cmath>

#include "sowing_robot/core/common/polygon.h"
#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

std::vector<Eigen::Vector2d> fieldGround(const FieldParams& field) {
  const Eigen::Vector2d u(std::cos(field.heading), std::sin(field.heading));
  const Eigen::Vector2d left(-u.y(), u.x());
  const Eigen::Vector2d side = field.rows_to_left ? left : Eigen::Vector2d(-left);
  const double margin = std::max(field.row_spacing, 2.0 * field.min_turn_radius);
  const double width = (field.rows - 1) * field.row_spacing;
  const Eigen::Vector2d a = Eigen::Vector2d(field.start_x, field.start_y) - margin * u - margin * side;
  const Eigen::Vector2d along = (field.row_length + 2.0 * margin) * u;
  const Eigen::Vector2d across = (width + 2.0 * margin) * side;
  return {a, a + along, a + along + across, a + across};
}

std::string patchesOutsideField(const FieldParams& field, const std::vector<SoilPatch>& patches,
                                const std::string& key) {
  const std::vector<Eigen::Vector2d> ground = fieldGround(field);
  std::string names;
  for (std::size_t i = 0; i < patches.size(); ++i)
    if (!ringsOverlap(patches[i].polygon, ground))
      names += (names.empty() ? "" : ", ") + key + "[" + std::to_string(i) + "]";
  if (names.empty()) return "";
  return names + " lie(s) wholly outside the field's rows and headlands (" + formatNumber(field.rows) + " rows of " +
         formatNumber(field.row_length) + " m from (" + formatNumber(field.start_x) + ", " +
         formatNumber(field.start_y) + ")): no wheel on the rows or turns meets them (a patch in another frame?)";
}

}  // namespace core
}  // namespace sowing_robot
