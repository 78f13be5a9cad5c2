#include "sowing_robot/core/simulation/runner.h"

#include <cmath>
#include <limits>
#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/simulation/closed_loop.h"

namespace sowing_robot {
namespace core {

std::string Scenario::validate() const {
  std::string e =
      firstError({checkPositive("duration", duration, "s"), control_period_ns > 0 ? "" : "control_period must be > 0",
                  allFinite(start.x, start.y, start.theta) ? "" : "start pose must be finite",
                  std::isfinite(disturbance_phase) ? "" : "disturbance_phase must be finite", robot.validate(),
                  disturbance.validate(), kanayama.validate(), sliding.validate(),
                  outer == OuterKind::kanayama ? "" : pure_pursuit.validate(),
                  inner == InnerKind::pid ? pid.validate() : "", hold.validate()});
  return e;
}

std::string Scenario::controllerName() const {
  return std::string(outerName(outer)) + "+" + innerName(inner, sliding.adaptive);
}

std::int64_t Scenario::steps() const {
  return static_cast<std::int64_t>(std::llround(duration * 1e9 / static_cast<double>(control_period_ns)));
}

namespace {

// runClosedLoop's runs: the no-slip plant fed its own state, through the one loop (closed_loop.h).
template <typename Outer, typename Inner, typename Trace>
RunResult loop(const Scenario& sc, ReferenceSource& reference, Outer& outer, Inner& inner, bool keep_samples,
               Trace& trace, const RunStop& stop) {
  NoSlipPlant plant{Plant(sc.robot, sc.disturbance), sc.robot.L};
  StateFeed feed;
  return closedLoop(sc, plant, feed, outer, inner, reference, keep_samples, trace, stop).run;
}

// The scenario's controllers as concrete types (direct calls in the loop).
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
