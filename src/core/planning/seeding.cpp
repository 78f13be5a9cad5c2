#include "sowing_robot/core/planning/seeding.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

std::vector<RowSegment> rowsOf(const FieldParams& field) {
  const FieldPath path(field);
  std::vector<RowSegment> rows;
  for (int i = 0; i < field.rows; ++i) {
    const double h = field.heading + (i % 2 == 0 ? 0.0 : M_PI);
    const Eigen::Vector2d a = path.rowStart(i);
    rows.push_back({a, a + field.row_length * unitVector(h)});
  }
  return rows;
}

const ParamTable<SeedingParams>& seedingTable() {
  using P = SeedingParams;
  static const ParamTable<P> table({
      number("spacing", &P::spacing, 0.1, Limits::positive(), "m", "distance between seeds along the tool's path"),
      number("tolerance", &P::tolerance, 0.02, Limits::positive(), "m",
             "cross-track error reported as \"off the line\" beyond this"),
      number("detour_margin", &P::detour_margin, 4.0, Limits::nonNegative(), "m",
             "seeds within radius + influence_distance + this of an obstacle are detour seeds, reported apart "
             "(the reference rejoins the row about 3 m after leaving the influence zone at 1 m/s)"),
      number("engage_distance", &P::engage_distance, 0.01, Limits::positive(), "m",
             "the tool is lowered once the tool point is this close to a row"),
  });
  return table;
}

SeedingParams::SeedingParams() { seedingTable().applyDefaults(*this); }

std::string SeedingParams::validate() const { return seedingTable().checkRanges(*this); }

SeedDrill::SeedDrill(const SeedingParams& params, std::vector<RowSegment> rows, std::vector<Obstacle> obstacles,
                     double influence)
    : params_(params), rows_(std::move(rows)), obstacles_(std::move(obstacles)), influence_(influence) {}

void SeedDrill::setPlan(std::vector<RowSegment> rows, std::vector<Obstacle> obstacles, double influence) {
  rows_ = std::move(rows);
  obstacles_ = std::move(obstacles);
  influence_ = influence;
}

double SeedDrill::crossTrack(const Eigen::Vector2d& p) const {
  double best = std::numeric_limits<double>::infinity();
  for (const RowSegment& r : rows_) {
    best = std::min(best, (p - (r.a + segmentParameter(p, r.a, r.b) * (r.b - r.a))).norm());
  }
  return best;
}

bool SeedDrill::onRowSegment(const Eigen::Vector2d& p) const {
  for (const RowSegment& r : rows_) {
    const Eigen::Vector2d ab = r.b - r.a;
    const double len2 = ab.squaredNorm();
    if (!(len2 > 0.0)) continue;
    const double u = (p - r.a).dot(ab) / len2;
    if (u > 0.0 && u < 1.0 && (p - (r.a + u * ab)).norm() <= params_.engage_distance) return true;
  }
  return false;
}

bool SeedDrill::inDetour(const Eigen::Vector2d& p) const {
  for (const Obstacle& o : obstacles_)
    if (std::hypot(p.x() - o.x, p.y() - o.y) < o.radius + influence_ + params_.detour_margin) return true;
  return false;
}

void SeedDrill::score(SeedStats& s, double& sum_sq, std::size_t& over, double e) {
  ++s.count;
  s.max = std::max(s.max, e);
  sum_sq += e * e;
  if (e > params_.tolerance) ++over;
  s.rms = std::sqrt(sum_sq / s.count);
  s.fraction_over = static_cast<double>(over) / s.count;
}

bool SeedDrill::update(const Eigen::Vector2d& p, bool tool_down, Eigen::Vector2d& seed) {
  if (!p.allFinite()) {
    ++rejected_;
    return false;
  }
  const bool first = !has_last_;
  const Eigen::Vector2d last = last_;
  has_last_ = true;
  last_ = p;
  if (!tool_down) lowered_ = false;
  if (tool_down && !lowered_ && onRowSegment(p)) {
    lowered_ = true;
    travelled_ = 0.0;
  }
  if (first || !lowered_) return false;
  travelled_ += (p - last).norm();
  if (travelled_ < params_.spacing) return false;
  travelled_ -= params_.spacing;
  seed = p;
  const double e = crossTrack(p);
  if (inDetour(p))
    score(detour_stats_, detour_sq_, detour_over_, e);
  else
    score(rows_stats_, rows_sq_, rows_over_, e);
  return true;
}

std::string SeedDrill::report() const {
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "seeds on rows: %zu, cross-track max %.4f m, RMS %.4f m, %.1f %% beyond %.3f m; "
                "detour seeds: %zu, max %.4f m, RMS %.4f m",
                rows_stats_.count, rows_stats_.max, rows_stats_.rms, 100.0 * rows_stats_.fraction_over,
                params_.tolerance, detour_stats_.count, detour_stats_.max, detour_stats_.rms);
  return buf;
}

}  // namespace core
}  // namespace sowing_robot
