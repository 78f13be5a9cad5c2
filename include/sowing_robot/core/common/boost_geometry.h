// The Boost.Geometry types the core's polygon code shares (the polygon checks of common/polygon.cpp, the coverage
// planner and its metrics) and their conversions from and to the interfaces' Eigen rings. For .cpp files only: the
// other headers keep to Eigen, so nothing else compiles Boost.Geometry.
#pragma once

#include <vector>

#include <Eigen/Dense>

// Boost 1.74's geometry reaches deprecated headers of other Boost parts; their notes are not ours to act on.
#define BOOST_ALLOW_DEPRECATED_HEADERS
#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>

namespace sowing_robot {
namespace core {
namespace geo {

namespace bg = boost::geometry;
using Point = bg::model::d2::point_xy<double>;
using Polygon = bg::model::polygon<Point>;  // clockwise, closed: bg::correct puts a ring in that order

inline Point toPoint(const Eigen::Vector2d& p) { return Point(p.x(), p.y()); }
inline Eigen::Vector2d toVector(const Point& p) { return {p.x(), p.y()}; }

/// A polygon from a ring in either orientation (not closed), closed and oriented as Boost expects.
inline Polygon toPolygon(const std::vector<Eigen::Vector2d>& ring) {
  Polygon poly;
  for (const Eigen::Vector2d& p : ring) poly.outer().push_back(toPoint(p));
  bg::correct(poly);
  return poly;
}

}  // namespace geo
}  // namespace core
}  // namespace sowing_robot
