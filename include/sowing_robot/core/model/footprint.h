// The robot's footprint: a convex polygon in base_link (x forward, y left, the axle midpoint at the
// origin), as projected from the URDF's collision geometry (sowing_robot::footprintFromUrdf). Used to
// inflate obstacles for the reference and to check the body against obstacles (ContactMonitor).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "sowing_robot/core/common/types.h"

namespace sowing_robot {
namespace core {

class Footprint {
 public:
  /// An empty footprint (no vertices): the robot is a point at base_link's origin.
  Footprint() = default;
  /// The convex hull of the points [m, base_link] (any order; duplicates and interior points dropped).
  static Footprint convexHull(std::vector<Eigen::Vector2d> points);

  /// "" or one line: at least 3 vertices, finite, counter-clockwise convex, base_link's origin inside.
  std::string validate() const;
  bool empty() const { return vertices_.empty(); }
  /// Vertices, counter-clockwise [m, base_link].
  const std::vector<Eigen::Vector2d>& vertices() const { return vertices_; }

  /// Largest distance of a vertex from base_link's origin: a disc of this radius about the axle midpoint
  /// holds the body at every heading [m]. 0 for an empty footprint.
  double circumscribedRadius() const;
  /// Smallest distance from base_link's origin to an edge: a disc of this radius about the axle
  /// midpoint is inside the body [m]. 0 for an empty footprint.
  double inscribedRadius() const;
  /// Signed distance of base_link-frame point q from the polygon [m]: > 0 outside, < 0 inside (minus the
  /// depth to the nearest edge). For an empty footprint, |q|.
  double signedDistance(const Eigen::Vector2d& q) const;
  /// Signed distance between the footprint placed at `pose` (base_link in the world) and a disc of
  /// `radius` about `centre` (world) [m]: the gap when apart, minus the penetration depth (the shortest
  /// move that separates them) when they overlap.
  double distanceToCircle(const Pose2D& pose, const Eigen::Vector2d& centre, double radius) const;
  /// Vertices placed at `pose`, in the world frame [m].
  std::vector<Eigen::Vector2d> placed(const Pose2D& pose) const;

 private:
  std::vector<Eigen::Vector2d> vertices_;
};

}  // namespace core
}  // namespace sowing_robot
