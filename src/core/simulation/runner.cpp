#include "sowing_robot/core/simulation/runner.h"

#include "sowing_robot/core/simulation/closed_loop.h"

namespace sowing_robot {
namespace core {

namespace {

// runClosedLoop's runs: the no-slip plant fed its own state, through the one loop (closed_loop.h).
template <typename Outer, typename Inner, typename Trace>
RunResult loop(const Scenario& sc, ReferenceSource& reference, Outer& outer, Inner& inner, bool keep_samples,
               Trace& trace, const RunStop& stop) {
  NoSlipPlant plant{Plant(sc.robot, sc.disturbance), sc.robot.L};
  StateFeed feed;
  return closedLoop(sc, plant, feed, outer, inner, reference, keep_samples, trace, stop).run;
}

// The scenario's controllers as the factory's concrete types (direct calls in the loop).
template <typename Trace>
RunResult withScenarioControllers(const Scenario& sc, ReferenceSource& reference, bool keep_samples, Trace& trace,
                                  const RunStop& stop) {
  return withControllers(sc, sc.robot, [&](auto& outer, auto& inner) {
    return loop(sc, reference, outer, inner, keep_samples, trace, stop);
  });
}

}  // namespace

RunResult runClosedLoop(const Scenario& sc, ReferenceSource& reference, bool keep_samples,
                        const std::function<void(const LoopSample&)>& trace, const RunStop& stop) {
  return withScenarioControllers(sc, reference, keep_samples, trace, stop);
}

RunResult runClosedLoop(const Scenario& sc, ReferenceSource& reference, bool keep_samples, RunTally& tally) {
  return withScenarioControllers(sc, reference, keep_samples, tally, RunStop{});
}

RunResult runClosedLoop(const Scenario& sc, ReferenceSource& reference, OuterController& outer, InnerController& inner,
                        bool keep_samples, const std::function<void(const LoopSample&)>& trace, const RunStop& stop) {
  outer.reset();
  inner.reset();
  return loop(sc, reference, outer, inner, keep_samples, trace, stop);
}

}  // namespace core
}  // namespace sowing_robot
