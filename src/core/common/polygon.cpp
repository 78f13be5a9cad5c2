#include "sowing_robot/core/common/polygon.h"

#include <cmath>

#include "sowing_robot/core/common/boost_geometry.h"

namespace sowing_robot {
namespace core {

namespace {
namespace bg = geo::bg;
using geo::Point;
using geo::Polygon;
using geo::toPolygon;
}  // namespace

double ringArea(const std::vector<Eigen::Vector2d>& ring) {
  if (ring.size() < 3) return 0.0;
  return std::abs(bg::area(toPolygon(ring)));
}

std::string ringProblem(const std::vector<Eigen::Vector2d>& ring) {
  const Polygon p = toPolygon(ring);
  bg::validity_failure_type failure;
  const bool valid = bg::is_valid(p, failure);
  const std::string reason = std::string("Boost.Geometry: ") + bg::validity_failure_type_message(failure);
  // Self-intersections are told before the area: a bow-tie's two lobes can cancel in the signed area. A balanced
  // one (signed area 0) is reported by is_valid as of the wrong orientation, as correct() cannot orient it: there
  // the self-intersection test tells a bow-tie from a line.
  if (!valid && failure == bg::failure_self_intersections) return "crosses itself (" + reason + ")";
  if (!valid && failure == bg::failure_wrong_orientation && bg::intersects(p))
    return "crosses itself (its edges cross and its lobes' areas cancel; " + reason + ")";
  if (std::abs(bg::area(p)) < kMinRingArea) return "has zero area (its vertices lie on one line or point)";
  if (valid) return "";
  if (failure == bg::failure_spikes) return "has a spike (an edge that doubles back on itself; " + reason + ")";
  return "is not a simple polygon (" + reason + ")";
}

bool ringsOverlap(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  const Polygon pa = toPolygon(a), pb = toPolygon(b);
  return bg::intersects(pa, pb) && !bg::touches(pa, pb);
}

bool ringCoveredBy(const std::vector<Eigen::Vector2d>& inner, const std::vector<Eigen::Vector2d>& outer) {
  return bg::covered_by(toPolygon(inner), toPolygon(outer));
}

bool circleCoveredBy(const Eigen::Vector2d& centre, double radius, const std::vector<Eigen::Vector2d>& ring) {
  const Polygon p = toPolygon(ring);
  const Point c(centre.x(), centre.y());
  if (!bg::covered_by(c, p)) return false;
  // The distance to the edges, segment by segment: to the areal ring it would be 0 for any point inside.
  const auto& r = p.outer();
  for (std::size_t i = 0; i + 1 < r.size(); ++i)
    if (bg::distance(c, bg::model::segment<Point>(r[i], r[i + 1])) < radius) return false;
  return true;
}

bool circleOverlapsRing(const Eigen::Vector2d& centre, double radius, const std::vector<Eigen::Vector2d>& ring) {
  const Polygon p = toPolygon(ring);
  return bg::distance(geo::toPoint(centre), p) < radius;
}

}  // namespace core
}  // namespace sowing_robot
