#include "sowing_robot/core/model/footprint.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sowing_robot {
namespace core {

namespace {
double cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
}

/// Distance from q to the segment a-b.
double segmentDistance(const Eigen::Vector2d& q, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (q - (a + segmentParameter(q, a, b) * (b - a))).norm();
}
}  // namespace

Footprint Footprint::convexHull(std::vector<Eigen::Vector2d> pts) {
  // Andrew's monotone chain; collinear points are dropped.
  std::sort(pts.begin(), pts.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  Footprint f;
  if (pts.size() < 3) {
    f.vertices_ = pts;
    return f;
  }
  std::vector<Eigen::Vector2d> h(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0.0) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], pts[i - 1]) <= 0.0) --k;
    h[k++] = pts[i - 1];
  }
  h.resize(k - 1);
  f.vertices_ = h;
  return f;
}

std::string Footprint::validate() const {
  const std::size_t n = vertices_.size();
  if (n < 3) return "footprint needs at least 3 vertices (has " + std::to_string(n) + ")";
  for (const auto& v : vertices_)
    if (!v.allFinite()) return "footprint vertex is not finite";
  for (std::size_t i = 0; i < n; ++i)
    if (!(cross(vertices_[i], vertices_[(i + 1) % n], vertices_[(i + 2) % n]) > 0.0))
      return "footprint is not a counter-clockwise convex polygon (at vertex " + std::to_string((i + 1) % n) + ")";
  if (!(signedDistance(Eigen::Vector2d::Zero()) < 0.0)) return "footprint does not contain base_link's origin";
  return "";
}

double Footprint::circumscribedRadius() const {
  double r = 0.0;
  for (const auto& v : vertices_) r = std::max(r, v.norm());
  return r;
}

double Footprint::inscribedRadius() const {
  if (vertices_.size() < 3) return 0.0;
  return std::max(0.0, -signedDistance(Eigen::Vector2d::Zero()));
}

double Footprint::signedDistance(const Eigen::Vector2d& q) const {
  const std::size_t n = vertices_.size();
  if (n == 0) return q.norm();
  double d = std::numeric_limits<double>::infinity();
  bool inside = n >= 3;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = vertices_[i];
    const Eigen::Vector2d& b = vertices_[(i + 1) % n];
    d = std::min(d, segmentDistance(q, a, b));
    if (cross(a, b, q) < 0.0) inside = false;  // right of a counter-clockwise edge: outside
  }
  return inside ? -d : d;
}

double Footprint::distanceToCircle(const Pose2D& pose, const Eigen::Vector2d& centre, double radius) const {
  // The centre in base_link: rotate the offset by -theta.
  double s, c;
  s = std::sin(pose.theta);
  c = std::cos(pose.theta);
  const Eigen::Vector2d w = centre - Eigen::Vector2d(pose.x, pose.y);
  const Eigen::Vector2d q(c * w.x() + s * w.y(), -s * w.x() + c * w.y());
  return signedDistance(q) - radius;
}

std::vector<Eigen::Vector2d> Footprint::placed(const Pose2D& pose) const {
  double s, c;
  s = std::sin(pose.theta);
  c = std::cos(pose.theta);
  std::vector<Eigen::Vector2d> out;
  out.reserve(vertices_.size());
  for (const auto& v : vertices_) out.emplace_back(pose.x + c * v.x() - s * v.y(), pose.y + s * v.x() + c * v.y());
  return out;
}

}  // namespace core
}  // namespace sowing_robot
