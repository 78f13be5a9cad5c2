#include "sowing_robot/core/control/command_limits.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sowing_robot {
namespace core {

const ParamTable<CommandLimitsParams>& commandLimitsTable() {
  using P = CommandLimitsParams;
  static const ParamTable<P> table({
      flag("limits/enabled", &P::enabled, false,
           "bound the outer loop's velocity command (value and change per second) before the inner loop; false: "
           "the command passes unchanged"),
      // The defaults are the field profile's (docs/drive_train.md, "Command limits": why these).
      number("limits/max_v", &P::max_v, 2.0, Limits::positive(), "m/s",
             "bound on |v| of the command (room to catch up a 1 m/s reference, below the motors' 2.9 m/s no-load rim "
             "speed)"),
      number("limits/max_omega", &P::max_omega, 3.0, Limits::positive(), "rad/s", "bound on |omega| of the command"),
      number("limits/max_acceleration", &P::max_acceleration, 0.6, Limits::positive(), "m/s^2",
             "bound on how fast the commanded v changes (about half what wet soil, mu 0.3, carries with the draft)"),
      number("limits/max_angular_accel", &P::max_angular_accel, 6.0, Limits::positive(), "rad/s^2",
             "bound on how fast the commanded omega changes (below ~3 Kanayama's field gains weave about the line)"),
  });
  return table;
}

CommandLimitsParams::CommandLimitsParams() { commandLimitsTable().applyDefaults(*this); }

std::string CommandLimitsParams::validate() const { return commandLimitsTable().checkRanges(*this); }

CommandLimiter::CommandLimiter(const CommandLimitsParams& params) : params_(params) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
}

namespace {

/// One axis: `value` clamped to +-max and to within step of `last`; `rate` its derivative to hand on.
double limitAxis(double value, double& rate, double last, double max, double max_rate, double dt, bool& limited) {
  const double step = max_rate * dt;
  const double out = std::clamp(std::clamp(value, -max, max), last - step, last + step);
  if (out != value) {
    limited = true;
    rate = (out - last) / dt;
  }
  return out;
}

}  // namespace

VelocityCommand CommandLimiter::limit(const VelocityCommand& cmd, double dt) {
  limiting_ = false;
  if (!params_.enabled) return cmd;
  if (cmd.hold) {
    reset();
    return cmd;
  }
  if (!(std::isfinite(cmd.v) && std::isfinite(cmd.omega))) return cmd;  // the inner loop's to refuse, as without
  VelocityCommand out = cmd;
  out.v = v_ = limitAxis(cmd.v, out.v_dot, v_, params_.max_v, params_.max_acceleration, dt, limiting_);
  out.omega = omega_ =
      limitAxis(cmd.omega, out.omega_dot, omega_, params_.max_omega, params_.max_angular_accel, dt, limiting_);
  return out;
}

}  // namespace core
}  // namespace sowing_robot
