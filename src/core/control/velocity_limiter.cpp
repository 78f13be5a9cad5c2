#include "sowing_robot/core/control/velocity_limiter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sowing_robot {
namespace core {

const ParamTable<VelocityLimits>& velocityLimitsTable() {
  using S = VelocityLimits;
  static const ParamTable<S> table({
      number("linear/max_velocity", &S::v_max, 1.0, Limits::positive(), "m/s",
             "bound on |v|, forward and in reverse; a cmd_vel beyond it is dropped"),
      number("linear/max_acceleration", &S::v_acceleration, 0.5, Limits::positive(), "m/s^2", "bound on |v_dot|"),
      number("linear/max_jerk", &S::v_jerk, 2.0, Limits::positive(), "m/s^3", "bound on the rate of change of v_dot"),
      number("angular/max_velocity", &S::omega_max, 1.0, Limits::positive(), "rad/s",
             "bound on |omega|, both ways; a cmd_vel beyond it is dropped"),
      number("angular/max_acceleration", &S::omega_acceleration, 1.0, Limits::positive(), "rad/s^2",
             "bound on |omega_dot|"),
      number("angular/max_jerk", &S::omega_jerk, 4.0, Limits::positive(), "rad/s^3",
             "bound on the rate of change of omega_dot"),
  });
  return table;
}

VelocityLimits::VelocityLimits() { velocityLimitsTable().applyDefaults(*this); }

std::string VelocityLimits::validate() const { return velocityLimitsTable().checkRanges(*this); }

double JerkProfile::duration() const { return phases[0].duration + phases[1].duration + phases[2].duration; }

AxisState JerkProfile::at(const AxisState& start, double t) const {
  if (t >= duration()) return {target, 0.0};  // the end exactly, not the sum of rounded phases
  AxisState s = start;
  double left = t;
  for (const Phase& p : phases) {
    const double h = std::min(p.duration, left);
    if (h <= 0.0) continue;  // a phase of no length (none left, or the peak held already)
    s.value += s.acceleration * h + 0.5 * p.jerk * h * h;
    s.acceleration += p.jerk * h;
    left -= h;
  }
  return s;
}

JerkProfile planProfile(const AxisState& s, double target, const AxisLimits& limits) {
  JerkProfile p;
  p.target = std::clamp(target, -limits.max_velocity, limits.max_velocity);
  const double jerk = limits.max_jerk, max_acc = limits.max_acceleration;
  const double a = s.acceleration;
  // Where the value comes to rest if the acceleration is taken to zero at once (at full jerk).
  const double settles_at = s.value + a * std::abs(a) / (2.0 * jerk);
  if (settles_at == p.target) {
    p.phases[0] = {a > 0.0 ? -jerk : jerk, std::abs(a) / jerk};
    return p;
  }
  // In the frame where the value must rise (dir = -1 mirrors a fall): from acceleration a_n up to a
  // peak at full jerk, hold the peak, down to zero at full jerk, gaining dv in all.
  const double dir = p.target > settles_at ? 1.0 : -1.0;
  const double a_n = dir * a, dv = dir * (p.target - s.value);
  // Unbounded peak: (peak^2 - a_n^2) / 2J on the way up plus peak^2 / 2J on the way down make dv. It is
  // above a_n (and above 0) because the target lies beyond settles_at.
  double peak = std::sqrt(std::max(0.0, jerk * dv + 0.5 * a_n * a_n));
  double hold = 0.0;
  if (peak > max_acc) {
    peak = max_acc;
    const double ramps = (a_n + peak) * std::abs(peak - a_n) / (2.0 * jerk) + peak * peak / (2.0 * jerk);
    hold = std::max(0.0, (dv - ramps) / peak);  // negative only from outside the bounds (|a| > max_acc)
  }
  p.phases[0] = {peak >= a_n ? dir * jerk : -dir * jerk, std::abs(peak - a_n) / jerk};
  p.phases[1] = {0.0, hold};
  p.phases[2] = {-dir * jerk, peak / jerk};
  return p;
}

VelocityLimiter::VelocityLimiter(const VelocityLimits& limits)
    : limits_(limits), linear_(limits.linear()), angular_(limits.angular()) {
  const std::string error = limits.validate();
  if (!error.empty()) throw std::invalid_argument(error);
}

void VelocityLimiter::advance(double v, double omega, double dt) {
  if (!(dt > 0.0)) return;
  v_ = planProfile(v_, v, linear_).at(v_, dt);
  omega_ = planProfile(omega_, omega, angular_).at(omega_, dt);
}

bool VelocityLimiter::withinBounds(double v, double omega) const {
  return std::abs(v) <= limits_.v_max && std::abs(omega) <= limits_.omega_max;
}

}  // namespace core
}  // namespace sowing_robot
