#include "sowing_robot/core/simulation/runner.h"

#include <cmath>
#include <limits>
#include <type_traits>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

std::string Scenario::validate() const {
  std::string e = firstError(
      {checkPositive("duration", duration, "s"), control_period_ns > 0 ? "" : "control_period must be > 0",
       allFinite(start.x, start.y, start.theta) ? "" : "start pose must be finite",
       std::isfinite(disturbance_phase) ? "" : "disturbance_phase must be finite", robot.validate(),
       disturbance.validate(), kanayama.validate(), sliding.validate(),
       outer == OuterKind::kanayama ? "" : pure_pursuit.validate(), inner == InnerKind::pid ? pid.validate() : ""});
  return e;
}

std::string Scenario::controllerName() const {
  return std::string(outerName(outer)) + "+" + innerName(inner, sliding.adaptive);
}

std::int64_t Scenario::steps() const {
  return static_cast<std::int64_t>(std::llround(duration * 1e9 / static_cast<double>(control_period_ns)));
}

namespace {

// One run's state through the loop, over concrete controller types (no virtual call when they are final or
// plain classes): Outer::compute(ref, pose, v, omega) -> VelocityCommand; Inner::update(cmd, v, omega, dt)
// -> InnerOutput, m0Hat(), i0Hat(). Trace: the public API's std::function (may be empty), or a RunTally
// (its add() inlined here, and what it does not read of the LoopSample never built).
template <typename Outer, typename Inner, typename Trace>
struct LoopRun {
  LoopRun(const Scenario& scenario, ReferenceSource& ref, Outer& o, Inner& i, bool keep_samples, Trace& tr,
          const RunStop& st)
      : sc(scenario),
        reference(ref),
        outer(o),
        inner(i),
        trace(tr),
        stop(st),
        plant(scenario.robot, scenario.disturbance),
        n(scenario.steps()),
        dt(secondsFromNanos(scenario.control_period_ns)),
        metrics(keep_samples) {
    plant.reset(startState(sc), phaseStartTime(sc));
    reference.reset();
    metrics.reserve(static_cast<std::size_t>(n + 1));
  }

  /// Period k up to its torques (tau_right, tau_left, for stepPlant()). False: the run ends at k (the state
  /// diverged, or stop() said so) and the plant must not step.
  bool control(std::int64_t k) { return observe() && controlObserved(k); }

  /// The state as the controllers receive it in nav_msgs/Odometry. False: the state diverged.
  bool observe() {
    const State& s = plant.state();
    if (!finiteSum(s)) {
      result.diverged = true;
      return false;
    }
    pose = Pose2D{s[X], s[Y], yawThroughQuaternion(s[THETA])};
    return true;
  }

  /// control(k) after observe().
  bool controlObserved(std::int64_t k) {
    const double t = secondsFromNanos(k * sc.control_period_ns);
    const State& s = plant.state();
    const Reference& ref = reference.next(t);  // the source's copy, valid until the next call
    double ex, ey, eth;
    worldErrors(ref, pose, ex, ey, eth);
    metrics.add(t, ex, ey, eth);
    // Initialised from the call (not assigned): the controller writes the command in place.
    const VelocityCommand cmd = outer.compute(ref, pose, s[V], s[OMEGA]);
    // A local, not a member: assigned to one, the result would be copied 16 bytes at a time out of
    // fields just stored 8 bytes at a time (store-forwarding stalls); the torques are taken field by field.
    const InnerOutput u = inner.update(cmd, s[V], s[OMEGA], dt);
    if (u.saturated) ++result.saturated_steps;
    if constexpr (std::is_same_v<Trace, RunTally>)
      trace.add({t, &s, &ref, &cmd, &u, inner.m0Hat(), inner.i0Hat(), ex, ey, eth});
    else if (trace)
      trace({t, &s, &ref, &cmd, &u, inner.m0Hat(), inner.i0Hat(), ex, ey, eth});
    result.periods = k;
    if (stop && k % kStopCheckEvery == kStopCheckEvery - 1 && k < n && stop(metrics)) {
      result.stopped = true;
      return false;
    }
    tau_right = u.torques.right;
    tau_left = u.torques.left;
    return true;
  }

  /// The plant's step with this period's torques.
  void stepPlant() { plant.step(tau_right, tau_left, dt); }
  /// Periods from `from` to the end (or to an earlier end of the run).
  void runFrom(std::int64_t from) {
    for (std::int64_t k = from; k <= n; ++k) {
      if (!control(k)) break;
      if (k < n) stepPlant();
    }
  }

  RunResult finish() {
    closeRun(result, plant.state(), metrics);
    return result;
  }

  const Scenario& sc;
  ReferenceSource& reference;
  Outer& outer;
  Inner& inner;
  Trace& trace;
  const RunStop& stop;
  Plant plant;
  const std::int64_t n;
  const double dt;
  MetricsAccumulator metrics;
  RunResult result;
  Pose2D pose;
  double tau_right = 0.0, tau_left = 0.0;
};

template <typename Outer, typename Inner, typename Trace>
RunResult loop(const Scenario& sc, ReferenceSource& reference, Outer& outer, Inner& inner, bool keep_samples,
               Trace& trace, const RunStop& stop) {
  LoopRun<Outer, Inner, Trace> run(sc, reference, outer, inner, keep_samples, trace, stop);
  run.runFrom(0);
  return run.finish();
}

template <typename Outer, typename Trace>
RunResult withInner(const Scenario& sc, ReferenceSource& reference, Outer& outer, bool keep_samples, Trace& trace,
                    const RunStop& stop) {
  if (sc.inner == InnerKind::pid) {
    InnerAdapter<WheelPid> pid{WheelPid(sc.pid, sc.robot)};
    return loop(sc, reference, outer, pid, keep_samples, trace, stop);
  }
  SlidingModeController smc(sc.sliding, sc.robot);
  return loop(sc, reference, outer, smc, keep_samples, trace, stop);
}

template <typename Trace>
RunResult withOuter(const Scenario& sc, ReferenceSource& reference, bool keep_samples, Trace& trace,
                    const RunStop& stop) {
  if (sc.outer == OuterKind::kanayama) {
    Kanayama kanayama(sc.kanayama);
    return withInner(sc, reference, kanayama, keep_samples, trace, stop);
  }
  PurePursuit pursuit(sc.pure_pursuit, sc.outer == OuterKind::rpp);
  return withInner(sc, reference, pursuit, keep_samples, trace, stop);
}

}  // namespace

RunResult runClosedLoop(const Scenario& sc, ReferenceSource& reference, bool keep_samples,
                        const std::function<void(const LoopSample&)>& trace, const RunStop& stop) {
  return withOuter(sc, reference, keep_samples, trace, stop);
}

RunResult runClosedLoop(const Scenario& sc, ReferenceSource& reference, bool keep_samples, RunTally& tally) {
  return withOuter(sc, reference, keep_samples, tally, RunStop{});
}

RunResult runClosedLoop(const Scenario& sc, ReferenceSource& reference, OuterController& outer, InnerController& inner,
                        bool keep_samples, const std::function<void(const LoopSample&)>& trace, const RunStop& stop) {
  outer.reset();
  inner.reset();
  return loop(sc, reference, outer, inner, keep_samples, trace, stop);
}

std::unique_ptr<OuterController> makeOuterController(const Scenario& sc) {
  if (sc.outer == OuterKind::kanayama) return std::make_unique<OuterAdapter<Kanayama>>(Kanayama(sc.kanayama));
  return std::make_unique<OuterAdapter<PurePursuit>>(PurePursuit(sc.pure_pursuit, sc.outer == OuterKind::rpp));
}

std::unique_ptr<InnerController> makeInnerController(const Scenario& sc) {
  if (sc.inner == InnerKind::pid) return std::make_unique<InnerAdapter<WheelPid>>(WheelPid(sc.pid, sc.robot));
  return std::make_unique<InnerAdapter<SlidingModeController>>(SlidingModeController(sc.sliding, sc.robot));
}

}  // namespace core
}  // namespace sowing_robot
