// The benchmark's runs of scenarios with sensors, traction or an estimate in the loop (the
// wet_soil and estimated_pose scenarios; BenchScenario::realism): one run of runBenchmark through runClosedLoop,
// measured and judged as today's runs are (benchmark.cpp's measure(): effort, chattering, time at the
// limit, cross-track after settle_time, body contacts and the finish check of a field), on the TRUTH,
// plus the figures of the estimated loop (slip, the fed pose's error, the fixes). Kept beside
// benchmark.cpp (not in its per-run hot path): test_estimated_run checks that a realism with the truth
// fed back and no traction gives today's rows bit for bit, so the two stay one measure.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sowing_robot/core/evaluation/benchmark.h"

namespace sowing_robot {
namespace core {

/// Run `index` of `bench` (bench.realism set): the run's draws (benchmark.h; sensors/seed from draw 8),
/// the scenario's track, runClosedLoop, the row. Throws std::invalid_argument for a bad scenario.
RunRow estimatedBenchRow(const BenchScenario& bench, std::int64_t index);

/// BenchScenario::validate()'s part for realism and requires_models: "" or one line.
std::string estimatedBenchCheck(const BenchScenario& bench);

/// A report line (Markdown paragraph) of a realism scenario's rows: slip, fed-pose error, fixes.
std::string estimatedReportLine(const std::vector<RunRow>& rows);
/// A sentence for the report's scenario list: plant, sensors and feedback of bench.realism ("" unset).
std::string describeRealism(const BenchScenario& bench);

}  // namespace core
}  // namespace sowing_robot
