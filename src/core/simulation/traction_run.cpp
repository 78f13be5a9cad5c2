#include "sowing_robot/core/simulation/traction_run.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sowing_robot {
namespace core {

TractionRunResult runTractionClosedLoop(const Scenario& sc, const TractionParams& traction, ReferenceSource& reference,
                                        bool keep_samples, const std::function<void(const LoopSample&)>& trace,
                                        const std::function<void(TractionPlant&)>& setup) {
  TractionPlant plant(sc.robot, sc.disturbance, traction);
  if (setup) setup(plant);
  plant.reset(startState(sc), 0.0);  // (the disturbance's phase is not applied here)
  Kanayama kanayama(sc.kanayama);
  SlidingModeController smc(sc.sliding, sc.robot);
  reference.reset();
  const std::int64_t n = sc.steps();
  const double dt = secondsFromNanos(sc.control_period_ns);
  MetricsAccumulator metrics(keep_samples);
  metrics.reserve(static_cast<std::size_t>(n + 1));
  TractionRunResult out;
  RunResult& result = out.run;

  for (std::int64_t k = 0; k <= n; ++k) {
    const double t = secondsFromNanos(k * sc.control_period_ns);
    const State& s = plant.state();
    if (!finiteSum(s)) {
      result.diverged = true;
      break;
    }
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
    if (k < n) {
      plant.step(u.torques.right, u.torques.left, dt);
      out.max_abs_slip =
          std::max({out.max_abs_slip, std::fabs(plant.slipRatio(RIGHT)), std::fabs(plant.slipRatio(LEFT))});
    }
  }
  closeRun(result, plant.state(), metrics);
  return out;
}

}  // namespace core
}  // namespace sowing_robot
