// Plane polygons given as their vertices (a ring: in order, either sense, not closed: the last vertex joins the
// first), checked and compared with Boost.Geometry (header-only; only this room's .cpp includes it): whether a ring
// is a simple polygon, its area, whether two overlap or one lies within another. Soil patches (model/soil_map.h)
// and field boundaries (planning/field_boundary.h, the field file) use them alike.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace sowing_robot {
namespace core {

/// |area| of the ring [m^2] (0 for fewer than 3 vertices).
double ringArea(const std::vector<Eigen::Vector2d>& ring);

/// Below this area a ring counts as zero-area (a line or a point drawn as a polygon) [m^2]: one square millimetre.
constexpr double kMinRingArea = 1e-6;

/// "" for a simple polygon, else why not in a few words with Boost.Geometry's is_valid reason: "crosses itself (...)",
/// "has zero area (...)", "has a spike (...)". The ring must have >= 3 finite vertices (check that first: the
/// callers name the vertex).
std::string ringProblem(const std::vector<Eigen::Vector2d>& ring);

/// The interiors of two simple rings share some area (touching along an edge or at a vertex is no overlap).
bool ringsOverlap(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b);
/// No point of `inner` lies outside `outer` (it may touch the edge from inside).
bool ringCoveredBy(const std::vector<Eigen::Vector2d>& inner, const std::vector<Eigen::Vector2d>& outer);
/// A circle (centre, radius) lies inside `ring` (it may touch the edge from inside).
bool circleCoveredBy(const Eigen::Vector2d& centre, double radius, const std::vector<Eigen::Vector2d>& ring);
/// A circle and a ring's interior share some area.
bool circleOverlapsRing(const Eigen::Vector2d& centre, double radius, const std::vector<Eigen::Vector2d>& ring);

}  // namespace core
}  // namespace sowing_robot
