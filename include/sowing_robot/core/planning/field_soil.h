// The soil patches against the field's rows: a patch that lies wholly outside the ground the robot drives (the
// rows and their headlands) never touches a wheel, most likely a patch in the wrong frame or of another field.
// That is a warning, not an error: the soil map describes the ground, not the plan, and one map may serve fields of
// fewer rows (a scenario set's small fields) or a start far off the rows (an approach) where the patch is met.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "sowing_robot/core/model/soil_map.h"
#include "sowing_robot/core/planning/field.h"

namespace sowing_robot {
namespace core {

/// The ground of the field's rows and turns: the rectangle the rows span, grown on every side by the headland
/// margin max(row_spacing, 2 min_turn_radius) (a turn does not reach further past a row's end), as a ring.
std::vector<Eigen::Vector2d> fieldGround(const FieldParams& field);

/// One warning line naming the patches (`key` "field/patches") wholly outside fieldGround(field), or "".
std::string patchesOutsideField(const FieldParams& field, const std::vector<SoilPatch>& patches,
                                const std::string& key = "field/patches");

}  // namespace core
}  // namespace sowing_robot
