// What the benchmark's two row writers share (benchmark.cpp for the ideal loop, estimated_bench.cpp for
// the loop with sensors and an estimate): the numbers of the CSV and of the report, and the lateral
// error both measure, so that a row means the same whichever loop made it.
#pragma once

#include <cmath>
#include <string>

#include "sowing_robot/core/runner.h"

namespace sowing_robot {
namespace core {

/// %.17g: a double that reads back to the same bits (runs.csv).
std::string csvNumber(double v);
/// %.4g (report.md).
std::string shortNumber(double v);

/// Lateral error in the reference's frame (cross-track for a line or a row).
inline double crossTrack(const LoopSample& s) {
  const double th = s.reference->pose.theta;
  // sin(+-0) = +-0 and cos(+-0) = 1 exactly: a line or a row along x needs no sincos every period.
  double sn = th, c = 1.0;
  if (th != 0.0) {
    sn = std::sin(th);
    c = std::cos(th);
  }
  return -sn * s.ex + c * s.ey;
}

}  // namespace core
}  // namespace sowing_robot
