// The Boost.Geometry operations the coverage planner and its metrics share (the types and conversions are
// common/boost_geometry.h's). For the planning room's .cpp files only: the other headers keep to Eigen, so nothing
// outside the coverage code compiles Boost.Geometry.
#pragma once

#include <vector>

#include "sowing_robot/core/common/boost_geometry.h"
#include "sowing_robot/core/planning/field_boundary.h"

namespace sowing_robot {
namespace core {
namespace geo {

using MultiPolygon = bg::model::multi_polygon<Polygon>;
using Line = bg::model::linestring<Point>;
using MultiLine = bg::model::multi_linestring<Line>;

/// Points on a full circle of the round joins and ends: a 0.55 m radius is then drawn with 9.6 cm chords, a 3 m
/// circle with 1.1 cm between its chords and the arc. More points cost time in every buffer.
constexpr int kPointsPerCircle = 36;

/// A ring's points without the closing repeat.
template <typename R>
Ring toRing(const R& ring) {
  Ring out;
  for (const Point& p : ring) out.push_back(toVector(p));
  if (out.size() > 1 && (out.front() - out.back()).norm() == 0.0) out.pop_back();
  return out;
}

/// The polygon grown (d > 0) or shrunk (d < 0) by |d|, round joins.
inline MultiPolygon offset(const MultiPolygon& in, double d) {
  if (d == 0.0 || in.empty()) return in;
  MultiPolygon out;
  bg::buffer(in, out, bg::strategy::buffer::distance_symmetric<double>(d), bg::strategy::buffer::side_straight(),
             bg::strategy::buffer::join_round(kPointsPerCircle), bg::strategy::buffer::end_round(kPointsPerCircle),
             bg::strategy::buffer::point_circle(kPointsPerCircle));
  return out;
}

/// The strip a tool of `width` sweeps along the lines (flat ends, round joins), the overlaps merged.
template <typename L>
MultiPolygon strip(const L& lines, double width) {
  MultiPolygon out;
  bg::buffer(lines, out, bg::strategy::buffer::distance_symmetric<double>(0.5 * width),
             bg::strategy::buffer::side_straight(), bg::strategy::buffer::join_round(kPointsPerCircle),
             bg::strategy::buffer::end_flat(), bg::strategy::buffer::point_circle(kPointsPerCircle));
  return out;
}

/// The circle as a polygon.
inline Polygon circle(const Eigen::Vector2d& c, double radius) {
  MultiPolygon out;
  bg::buffer(toPoint(c), out, bg::strategy::buffer::distance_symmetric<double>(radius),
             bg::strategy::buffer::side_straight(), bg::strategy::buffer::join_round(kPointsPerCircle),
             bg::strategy::buffer::end_round(kPointsPerCircle), bg::strategy::buffer::point_circle(kPointsPerCircle));
  return out.empty() ? Polygon() : out.front();
}

/// The field's outer boundary and its voids (polygons and circles) as Boost polygons (no checks).
inline Polygon outerPolygon(const FieldBoundary& f) { return toPolygon(f.outer); }
inline MultiPolygon voidPolygons(const FieldBoundary& f) {
  MultiPolygon voids;
  for (const Ring& v : f.voids) {
    MultiPolygon merged;
    bg::union_(voids, toPolygon(v), merged);
    voids = std::move(merged);
  }
  for (const Obstacle& o : f.circles) {
    MultiPolygon merged;
    bg::union_(voids, circle({o.x, o.y}, o.radius), merged);
    voids = std::move(merged);
  }
  return voids;
}
/// What is to be sown: the outer boundary minus the voids.
inline MultiPolygon workable(const FieldBoundary& f) {
  MultiPolygon out;
  bg::difference(outerPolygon(f), voidPolygons(f), out);
  return out;
}

}  // namespace geo
}  // namespace core
}  // namespace sowing_robot
