#include "sowing_robot/core/planning/tool_engagement.h"

namespace sowing_robot {
namespace core {

ToolEngagement::ToolEngagement(const SeedingParams& params, std::vector<RowSegment> rows, bool open_ended)
    : geometry_(params, std::move(rows), {}, 0.0), open_ended_(open_ended) {}

void ToolEngagement::setPlan(std::vector<RowSegment> rows, bool open_ended) {
  geometry_.setPlan(std::move(rows), {}, 0.0);
  open_ended_ = open_ended;
}

bool ToolEngagement::withinRows(const Eigen::Vector2d& p) const { return geometry_.withinRowSpan(p, open_ended_); }

bool ToolEngagement::update(const Eigen::Vector2d& p) {
  if (!p.allFinite()) return down_;
  if (down_ && !withinRows(p)) down_ = false;
  if (!down_ && geometry_.onRowSegment(p)) down_ = true;
  return down_;
}

}  // namespace core
}  // namespace sowing_robot
