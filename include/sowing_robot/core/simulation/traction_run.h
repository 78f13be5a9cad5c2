// The in-process closed loop of runner.h with the traction plant in place of the no-slip Plant: the same
// reference, Kanayama and sliding-mode steps in the same order, so the two runs differ only by the plant.
// A separate loop (not a template of runClosedLoop) so that today's hot path stays as it is.
#pragma once

#include <functional>

#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {
namespace core {

struct TractionRunResult {
  RunResult run;
  double max_abs_slip = 0.0;  ///< largest |slip ratio| of either wheel over the run
};

/// runClosedLoop() with TractionPlant(scenario.robot, scenario.disturbance, traction). `setup` (if
/// given) sees the plant before its reset: soil patches, normal loads, the tool (setToolDown). Throws
/// std::invalid_argument when a parameter set does not validate.
TractionRunResult runTractionClosedLoop(const Scenario& scenario, const TractionParams& traction,
                                        ReferenceSource& reference, bool keep_samples = true,
                                        const std::function<void(const LoopSample&)>& trace = {},
                                        const std::function<void(TractionPlant&)>& setup = {});

}  // namespace core
}  // namespace sowing_robot
