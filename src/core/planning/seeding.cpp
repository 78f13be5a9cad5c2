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
      number("depth_min", &P::depth_min, 0.03, Limits::positive(), "m",
             "shallowest depth of the agronomic band (maize, sunflower: 3-5 cm; seeds above it are counted)"),
      number("depth_max", &P::depth_max, 0.05, Limits::positive(), "m",
             "deepest depth of the agronomic band (seeds below it are counted)"),
  });
  return table;
}

SeedingParams::SeedingParams() { seedingTable().applyDefaults(*this); }

std::string SeedingParams::validate() const {
  const std::string e = seedingTable().checkRanges(*this);
  if (!e.empty()) return e;
  if (!(depth_min < depth_max))
    return "depth_min (" + std::to_string(depth_min) + " m) must be below depth_max (" + std::to_string(depth_max) +
           " m): the agronomic depth band is empty";
  return "";
}

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
    if (std::hypot(p.x() - o.x, p.y() - o.y) < detourRadius(o)) return true;
  return false;
}

int SeedDrill::nearestRow(const Eigen::Vector2d& p) const {
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    const RowSegment& r = rows_[i];
    const double d = (p - (r.a + segmentParameter(p, r.a, r.b) * (r.b - r.a))).norm();
    if (d < best_d) {
      best_d = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

void SeedDrill::score(SeedStats& s, double& sum_sq, std::size_t& over, double e) {
  ++s.count;
  s.max = std::max(s.max, e);
  sum_sq += e * e;
  if (e > params_.tolerance) ++over;
  s.rms = std::sqrt(sum_sq / s.count);
  s.fraction_over = static_cast<double>(over) / s.count;
}

bool SeedDrill::drop(double t, const Eigen::Vector2d& truth, const Eigen::Vector2d& believed, bool tool_down,
                     bool held_up, double depth, Seed& seed) {
  Eigen::Vector2d p;
  if (!update(truth, tool_down, p, held_up)) return false;
  seed.t = t;
  seed.truth = p;
  seed.believed = believed;
  seed.row = nearestRow(p);
  seed.depth = depth;
  seed.detour = inDetour(p);
  return true;
}

bool SeedDrill::withinRowSpan(const Eigen::Vector2d& p, bool open_ended) const {
  for (const RowSegment& r : rows_) {
    const Eigen::Vector2d ab = r.b - r.a;
    const double len2 = ab.squaredNorm();
    if (!(len2 > 0.0)) continue;
    const double u = (p - r.a).dot(ab) / len2;
    if (u > 0.0 && (u < 1.0 || open_ended)) return true;
  }
  return false;
}

bool SeedDrill::update(const Eigen::Vector2d& p, bool tool_down, Eigen::Vector2d& seed, bool held_up) {
  if (!p.allFinite()) {
    ++rejected_;
    return false;
  }
  const bool first = !has_last_;
  const Eigen::Vector2d last = last_;
  has_last_ = true;
  last_ = p;
  // A seed falls only on a row's stretch: the drill is lifted once the tool point passes a row's end, whatever the
  // plan asks (a robot that overshoots its last stop would sow the headland). After the plan's request has ended it
  // stays down only while the tool point is also on the row's line (within tolerance): a path that rounds its corner
  // before the row's end leaves it there.
  if (held_up || !withinRowSpan(p) || (!tool_down && crossTrack(p) > params_.tolerance)) lowered_ = false;
  if (tool_down && !held_up && !lowered_ && onRowSegment(p)) {
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
