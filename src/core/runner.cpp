#include "sowing_robot/core/runner.h"

#include <cmath>
#include <limits>

#include "sowing_robot/core/validation.h"

namespace sowing_robot {
namespace core {

std::string Scenario::validate() const {
  std::string e =
      firstError({checkPositive("duration", duration, "s"), control_period_ns > 0 ? "" : "control_period must be > 0",
                  allFinite(start.x, start.y, start.theta) ? "" : "start pose must be finite", robot.validate(),
                  disturbance.validate(), kanayama.validate(), sliding.validate()});
  return e;
}

std::int64_t Scenario::steps() const {
  return static_cast<std::int64_t>(std::llround(duration * 1e9 / static_cast<double>(control_period_ns)));
}

RunResult runClosedLoop(const Scenario& sc, ReferenceSource& reference, bool keep_samples,
                        const std::function<void(const LoopSample&)>& trace, const RunStop& stop) {
  Plant plant(sc.robot, sc.disturbance);
  State x0 = State::Zero();
  x0[X] = sc.start.x;
  x0[Y] = sc.start.y;
  x0[THETA] = sc.start.theta;
  plant.reset(x0, 0.0);
  Kanayama kanayama(sc.kanayama);
  SlidingModeController smc(sc.sliding, sc.robot);
  reference.reset();
  const std::int64_t n = sc.steps();
  const double dt = secondsFromNanos(sc.control_period_ns);
  MetricsAccumulator metrics(keep_samples);
  metrics.reserve(static_cast<std::size_t>(n + 1));
  RunResult result;

  for (std::int64_t k = 0; k <= n; ++k) {
    const double t = secondsFromNanos(k * sc.control_period_ns);
    const State& s = plant.state();
    if (!std::isfinite(s.sum())) {
      result.diverged = true;
      break;
    }
    // What the controllers receive in nav_msgs/Odometry.
    const Pose2D pose{s[X], s[Y], yawThroughQuaternion(s[THETA])};
    const Reference ref = reference.next(t);
    double ex, ey, eth;
    worldErrors(ref, pose, ex, ey, eth);
    metrics.add(t, ex, ey, eth);
    const VelocityCommand cmd = kanayama.compute(ref, pose, s[V], s[OMEGA]);
    const SlidingModeOutput u = smc.update(cmd, s[V], s[OMEGA], dt);
    if (u.saturated) ++result.saturated_steps;
    if (trace) trace({t, &s, &ref, &cmd, &u, smc.m0Hat(), smc.i0Hat(), ex, ey, eth});
    result.periods = k;
    if (stop && k % kStopCheckEvery == kStopCheckEvery - 1 && k < n && stop(metrics)) {
      result.stopped = true;
      break;
    }
    if (k < n) plant.step(u.torques.right, u.torques.left, dt);
  }
  result.final_state = plant.state();
  result.metrics = metrics.result();
  if (result.diverged) {
    const double inf = std::numeric_limits<double>::infinity();
    for (auto& m : result.metrics) m.ise = m.itse = m.iae = m.itae = inf;
  }
  return result;
}

}  // namespace core
}  // namespace sowing_robot
