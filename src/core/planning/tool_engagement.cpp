#include "sowing_robot/core/planning/tool_engagement.h"

namespace sowing_robot {
namespace core {

ToolEngagement::ToolEngagement(const SeedingParams& params, std::vector<RowSegment> rows, bool open_ended)
    : geometry_(params, rows, {}, 0.0), rows_(std::move(rows)), open_ended_(open_ended) {}

void ToolEngagement::setPlan(std::vector<RowSegment> rows, bool open_ended) {
  geometry_.setPlan(rows, {}, 0.0);
  rows_ = std::move(rows);
  open_ended_ = open_ended;
}

bool ToolEngagement::withinRows(const Eigen::Vector2d& p) const {
  for (const RowSegment& r : rows_) {
    const Eigen::Vector2d ab = r.b - r.a;
    const double len2 = ab.squaredNorm();
    if (!(len2 > 0.0)) continue;
    const double u = (p - r.a).dot(ab) / len2;
    if (u > 0.0 && (u < 1.0 || open_ended_)) return true;
  }
  return false;
}

bool ToolEngagement::update(const Eigen::Vector2d& p) {
  if (!p.allFinite()) return down_;
  if (down_ && !withinRows(p)) down_ = false;
  if (!down_ && geometry_.onRowSegment(p)) down_ = true;
  return down_;
}

}  // namespace core
}  // namespace sowing_robot
