#include "sowing_robot/core/control/cmd_vel_input.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sowing_robot {
namespace core {

const ParamTable<CmdVelParams>& CmdVelParams::table() {
  using S = CmdVelParams;
  static const ParamTable<S> table = [] {
    ParamTable<S> t({
        number("cmd_vel_timeout", &S::timeout, 0.5, Limits::closed(0.0, 1e6), "s",
               "a command older than this is stale: the limiter ramps the robot to a stop (simulated time); "
               "0 = never"),
    });
    return t.nest("", &S::limits, velocityLimitsTable());
  }();
  return table;
}

CmdVelParams::CmdVelParams() { table().applyDefaults(*this); }

const char* verdictText(CmdVerdict v) {
  switch (v) {
    case CmdVerdict::accepted: return "accepted";
    case CmdVerdict::non_finite: return "non-finite";
    case CmdVerdict::out_of_range: return "beyond the velocity limits";
    case CmdVerdict::late: return "stamped before the time already computed";
    case CmdVerdict::out_of_order: return "stamped before an earlier command";
    case CmdVerdict::full: return "too many commands waiting for their stamps";
  }
  return "?";
}

CmdVelInput::CmdVelInput(const CmdVelParams& params, bool strict)
    : params_(params),
      strict_(strict),
      timeout_ns_(static_cast<std::int64_t>(std::llround(params.timeout * 1e9))),
      limiter_(params.limits) {
  const std::string error = params.validate();
  if (!error.empty()) throw std::invalid_argument(error);
}

CmdVerdict CmdVelInput::offer(std::int64_t stamp, double v, double omega) {
  if (!allFinite(v, omega)) return CmdVerdict::non_finite;
  if (!limiter_.withinBounds(v, omega)) return CmdVerdict::out_of_range;
  if (any_ && stamp < newest_) return CmdVerdict::out_of_order;
  if (started_ && stamp < now_ && strict_) return CmdVerdict::late;
  if (queued_.size() >= kMaxQueued) return CmdVerdict::full;
  // Realtime: a command stamped in the past acts from now; two stamped alike, the later wins (absorb()).
  queued_.push_back({stamp, started_ ? std::max(stamp, now_) : stamp, v, omega});
  newest_ = stamp;
  any_ = true;
  return CmdVerdict::accepted;
}

void CmdVelInput::absorb() {
  while (!queued_.empty() && queued_.front().acts_from <= now_) {
    current_ = queued_.front();
    queued_.pop_front();
    has_current_ = true;
  }
}

bool CmdVelInput::stale() const { return has_current_ && timeout_ns_ > 0 && now_ - current_.stamp >= timeout_ns_; }

double CmdVelInput::age() const { return has_current_ ? secondsFromNanos(now_ - current_.stamp) : 0.0; }

VelocityCommand CmdVelInput::update(std::int64_t t) {
  if (!started_) {
    started_ = true;
    now_ = t;
    absorb();
    return limiter_.command();
  }
  // Piece by piece: the target is constant between the instants where a command starts to act or the
  // one in force goes stale.
  while (now_ < t) {
    absorb();
    std::int64_t end = t;
    if (!queued_.empty()) end = std::min(end, queued_.front().acts_from);
    const bool fresh = has_current_ && !stale();
    if (fresh && timeout_ns_ > 0) end = std::min(end, current_.stamp + timeout_ns_);
    limiter_.advance(fresh ? current_.v : 0.0, fresh ? current_.omega : 0.0, secondsFromNanos(end - now_));
    now_ = end;
  }
  absorb();
  return limiter_.command();
}

}  // namespace core
}  // namespace sowing_robot
