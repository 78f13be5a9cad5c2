#include "sowing_robot/core/planning/field_path_follower.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace sowing_robot {
namespace core {

namespace {
/// Time step of the sampling: well under the spacing at any field speed (row_speed <= 10 m/s).
constexpr double kSampleStep = 1e-3;  // [s]
/// A point where the path turns by less than this is on a straight [rad] (the rows are straight to round-off).
constexpr double kStraightAngle = 1e-6;

/// Without the points inside straight stretches (the tool's changes kept): a row is one segment, while a curve keeps
/// its even spacing. (Douglas-Peucker would leave uneven neighbours on a curve, and the follower turns in place at a
/// corner whose rounding does not fit in half of its shorter neighbour.)
CoveragePath dropStraightPoints(const CoveragePath& in) {
  CoveragePath out;
  const std::size_t n = in.points.size();
  for (std::size_t k = 0; k < n; ++k) {
    const bool inner = k > 0 && k + 1 < n && in.tool_down[k - 1] == in.tool_down[k];
    if (inner) {
      const Eigen::Vector2d a = in.points[k] - in.points[k - 1], b = in.points[k + 1] - in.points[k];
      if (std::fabs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b))) < kStraightAngle) continue;
    }
    out.points.push_back(in.points[k]);
    if (k + 1 < n) out.tool_down.push_back(in.tool_down[k]);
  }
  return out;
}
}  // namespace

CoveragePath coveragePath(const FieldPath& path, double spacing) {
  if (!(spacing > 0.0)) throw std::invalid_argument("coveragePath: spacing must be > 0");
  CoveragePath out;
  const double end = path.duration();
  TargetState s = path.at(0.0);
  out.points.push_back(s.p);
  bool tool = s.tool_down;
  const long steps = static_cast<long>(std::ceil(end / kSampleStep));
  for (long k = 1; k <= steps; ++k) {
    // at(end) already holds the end with the tool up: the last segment keeps the state before it.
    s = path.at(std::min(end, k * kSampleStep));
    const bool last = k == steps;
    const bool changed = s.tool_down != tool && !last;
    if (!changed && !last && (s.p - out.points.back()).norm() < spacing) continue;
    if ((s.p - out.points.back()).norm() < 1e-9) {  // at rest (a stop): nothing to add, the flag may change
      if (changed) tool = s.tool_down;
      continue;
    }
    out.points.push_back(s.p);
    out.tool_down.push_back(tool);
    if (changed) tool = s.tool_down;
  }
  return dropStraightPoints(out);
}

PathParams fieldFollowerParams(const FieldParams& field) {
  PathParams p;
  p.v_max = field.row_speed;
  p.a_max = field.max_accel;
  p.lateral_accel = field.turn_speed * field.turn_speed / field.min_turn_radius;
  p.max_curvature = 2.5 / field.min_turn_radius;
  p.simplify_tolerance = 0.0;  // the producer's points are exact (dropStraightPoints)
  p.goal_tolerance = 0.05;
  p.tool_down = false;  // the flags decide
  return p;
}

namespace {
/// The plan's start: the path's first point, heading along its first segment (the field's path starts where the robot
/// does, along its heading: a start heading off the sampled chord by round-off would be a turn in place).
Pose2D startOf(const CoveragePath& path) {
  const Eigen::Vector2d p = path.points.front();
  const Eigen::Vector2d d = path.points.size() > 1 ? Eigen::Vector2d(path.points[1] - p) : Eigen::Vector2d(1.0, 0.0);
  return Pose2D{p.x(), p.y(), std::atan2(d.y(), d.x())};
}
}  // namespace

FieldPathReference::FieldPathReference(const FieldParams& params, std::vector<Obstacle> obstacles)
    : params_(params),
      obstacles_(std::move(obstacles)),
      path_(std::make_shared<const FieldPath>(params_, obstacles_)),
      coverage_(coveragePath(*path_, kSpacing)),
      follower_(followerFromStart()) {}

PathReference FieldPathReference::followerFromStart() const {
  return PathReference(fieldFollowerParams(params_), startOf(coverage_), coverage_.points, coverage_.tool_down);
}

void FieldPathReference::restart() { follower_ = followerFromStart(); }

std::unique_ptr<ReferenceSource> FieldPathReference::clone() const {
  auto c = std::make_unique<FieldPathReference>(*this);
  c->reset();
  return c;
}

bool FieldPathReference::finished(double t) const { return t >= duration(); }

double FieldPathReference::duration() const { return follower_.planStart() + follower_.plan().duration(); }

void FieldPathReference::setObstacles(std::vector<Obstacle> obstacles) {
  auto path = std::make_shared<const FieldPath>(params_, obstacles);  // throws before anything changes
  CoveragePath coverage = coveragePath(*path, kSpacing);
  follower_.setPath(coverage.points, coverage.tool_down);
  path_ = std::move(path);
  coverage_ = std::move(coverage);
  obstacles_ = std::move(obstacles);
}

std::unique_ptr<FieldSource> makeFieldSource(const FieldParams& params, std::vector<Obstacle> obstacles) {
  if (params.follower == FieldFollower::kPath)
    return std::make_unique<FieldPathReference>(params, std::move(obstacles));
  return std::make_unique<FieldReference>(params, std::move(obstacles));
}

}  // namespace core
}  // namespace sowing_robot
