// A field as a farmer's software gives it: an outer boundary and the areas inside it not to be sown (a pond, a
// tree line, a pole), in the local ENU frame of the field (x east, y north, metres, REP-103/105: the odom frame's
// plane). Reading it from a file (local coordinates or WGS84 GeoJSON) is the field file's job; planning the
// headlands, swaths and route over it is the coverage planner's.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "sowing_robot/core/model/obstacle.h"

namespace sowing_robot {
namespace core {

/// A simple polygon: its vertices in order (either orientation), not closed (the last vertex joins the first).
using Ring = std::vector<Eigen::Vector2d>;

/// The outer boundary and the voids (polygons and circles) of one field, in the field's local frame [m].
struct FieldBoundary {
  Ring outer;
  std::vector<Ring> voids;
  std::vector<Obstacle> circles;  ///< circular voids (today's obstacles: a pole, a tree)
};

}  // namespace core
}  // namespace sowing_robot
