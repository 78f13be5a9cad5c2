// In-process closed loop: plant + outer controller (Kanayama by default) + inner controller (the
// sliding-mode controller by default) + reference, stepped exactly as the node pipeline steps them in
// lockstep (same order, same times, same yaw round trip), so the two give the same numbers. Used by
// tests, the metrics tool and the PSO tuner. The baselines (pure pursuit, RPP, wheel PID) are chosen by
// Scenario::outer / inner (controller_factory.h). The loop's types: loop_types.h.
#pragma once

#include <functional>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/simulation/loop_types.h"

namespace sowing_robot {
namespace core {

/// Run the scenario with the given reference. trace (optional) sees every period; keep_samples turns
/// on the time-domain figures (rise/settling/overshoot).
RunResult runClosedLoop(const Scenario& scenario, ReferenceSource& reference, bool keep_samples = true,
                        const std::function<void(const LoopSample&)>& trace = {}, const RunStop& stop = {});

/// The same run with a RunTally fed every period (inlined into the loop; the same numbers as a trace
/// callback calling tally.add()).
RunResult runClosedLoop(const Scenario& scenario, ReferenceSource& reference, bool keep_samples, RunTally& tally);

/// The same loop with caller-built controllers behind the run-time interfaces (virtual calls; the
/// Scenario's outer/inner choice and gains are then ignored, its plant, timing and start are used).
RunResult runClosedLoop(const Scenario& scenario, ReferenceSource& reference, OuterController& outer,
                        InnerController& inner, bool keep_samples = true,
                        const std::function<void(const LoopSample&)>& trace = {}, const RunStop& stop = {});

}  // namespace core
}  // namespace sowing_robot
