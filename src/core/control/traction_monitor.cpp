#include "sowing_robot/core/control/traction_monitor.h"

#include <cmath>
#include <cstdio>

namespace sowing_robot {
namespace core {

std::string NoTractionReport::text() const {
  char b[256];
  std::snprintf(b, sizeof(b),
                "no traction at (%.2f %.2f): the wheels slipped %.1f s of %.1f s with %.3f m of ground progress",
                where.x, where.y, slip, span, progress);
  return diagnosis.empty() ? std::string(b) : std::string(b) + "; " + diagnosis;
}

TractionMonitor::TractionMonitor(const TractionControlParams& params)
    : window_(params.no_traction_window),
      progress_(params.no_traction_progress),
      share_(params.no_traction_slip_share) {}

void TractionMonitor::reset() {
  anchored_ = false;
  slip_ = 0.0;
  report_ = NoTractionReport{};
}

bool TractionMonitor::update(double t, const Pose2D& fed, bool driving, bool slipping, double dt) {
  if (report_.detected) return true;
  if (!active() || !driving || !std::isfinite(fed.x) || !std::isfinite(fed.y)) {
    anchored_ = false;  // at a stop (or without a pose) the check rests and starts afresh
    return false;
  }
  const double moved = anchored_ ? std::hypot(fed.x - anchor_.x, fed.y - anchor_.y) : 0.0;
  if (!anchored_ || moved >= progress_) {  // progress made: a new window from here
    anchored_ = true;
    anchor_ = fed;
    t0_ = t;
    slip_ = 0.0;
    return false;
  }
  if (slipping) slip_ += dt;
  const double span = t - t0_;
  if (span >= window_ && slip_ >= share_ * span) {
    report_.detected = true;
    report_.t = t;
    report_.where = fed;
    report_.slip = slip_;
    report_.span = span;
    report_.progress = moved;
  }
  return report_.detected;
}

}  // namespace core
}  // namespace sowing_robot
