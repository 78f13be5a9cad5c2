// In-process closed loop: plant + outer controller (Kanayama by default) + inner controller (the
// sliding-mode controller by default) + reference, stepped exactly as the node pipeline steps them in
// lockstep (same order, same times, same yaw round trip), so the two give the same numbers. Used by
// tests, the metrics tool and the PSO tuner. The baselines (pure pursuit, RPP, wheel PID) are chosen by
// Scenario::outer / inner (controllers.h).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/control/controllers.h"
#include "sowing_robot/core/control/kanayama.h"
#include "sowing_robot/core/control/sliding_mode.h"
#include "sowing_robot/core/control/standstill_hold.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/simulation/metrics.h"

namespace sowing_robot {
namespace core {

struct Scenario {
  double duration = 25.0;                    ///< simulated time [s]
  std::int64_t control_period_ns = 1000000;  ///< plant step and control period [ns] (1 kHz)
  Pose2D start{-1.0, 0.0, 0.0};              ///< initial posture of the axle midpoint
  RobotParams robot;                         ///< nominal parameters (the controllers' model)
  PlantDisturbance disturbance;              ///< what the plant adds (disturbance, noise, mismatch)
  /// Phase of the sinusoidal disturbance [rad]: the plant's clock starts at phase / frequency (the
  /// disturbance is its only user). 0: the thesis's (and the nodes') zero phase.
  double disturbance_phase = 0.0;
  KanayamaGains kanayama;
  SlidingModeParams sliding;
  OuterKind outer = OuterKind::kanayama;      ///< which outer controller runClosedLoop builds
  InnerKind inner = InnerKind::sliding_mode;  ///< which inner controller (atsmc/tsmc: sliding.adaptive)
  PurePursuitParams pure_pursuit;             ///< outer = pure_pursuit or rpp
  WheelPidParams pid;                         ///< inner = pid
  StandstillHoldParams hold;                  ///< the brake at a stop in the plan (closed_loop.h, step 4)

  /// "kanayama+atsmc", "rpp+pid", ...
  std::string controllerName() const;

  std::string validate() const;
  /// Number of control periods; states are evaluated at k = 0..steps() inclusive.
  std::int64_t steps() const;
};

/// One control period of the loop, as seen by a trace callback.
struct LoopSample {
  double t;
  const State* state;
  const Reference* reference;
  const VelocityCommand* desired;
  const InnerOutput* control;  ///< for a PID inner: see InnerOutput (s_v = s_omega = 0)
  double m0_hat, i0_hat;       ///< a non-adaptive inner reports its fixed model values
  double ex, ey, etheta;       ///< world-frame errors
};

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

/// The per-period figures of a benchmark row (core/evaluation/bench_row.h's RowMeter) beyond the metrics, added up
/// sample by sample: the wheel-torque effort and its total variation, the cross-track error (its worst
/// after settle_time, its last, a series every series_every periods). runClosedLoop takes one directly
/// (below), so a run that needs nothing else per period has them without a trace callback: no
/// std::function call and no LoopSample built every period (docs/performance.md).
struct RunTally {
  // Set before the run:
  double dt = 0.0;                ///< control period [s]
  double settle_time = 0.0;       ///< worst_cross_track counts from here [s]
  std::int64_t series_every = 0;  ///< cross-track into *series every this many periods (0: none)
  std::vector<double>* series = nullptr;
  // The figures:
  double effort = 0.0;             ///< integral of tau_r^2 + tau_l^2 [N^2·m^2·s]
  double chattering = 0.0;         ///< sum |delta tau_r| + |delta tau_l| [N·m]
  double worst_cross_track = 0.0;  ///< max |cross-track| from settle_time on [m]
  double last_cross_track = 0.0;   ///< |cross-track| of the last sample [m]

  void add(const LoopSample& s) {
    // A period's torque is applied over the next dt: count it when the next sample arrives, so the
    // last one (never applied) is left out of the effort and of the total variation.
    if (count_ >= 1) effort += dt * (prev_.right * prev_.right + prev_.left * prev_.left);
    if (count_ >= 2) chattering += std::fabs(prev_.right - prev2_.right) + std::fabs(prev_.left - prev2_.left);
    const double e = crossTrack(s);
    if (series_every > 0) {  // at count = 0, series_every, 2 series_every, ... (no % per period)
      if (until_series_ == 0) {
        series->push_back(e);
        until_series_ = series_every;
      }
      --until_series_;
    }
    // Field by field: a struct copy is two 16-byte moves, and the inner controller has just written its
    // output 8 bytes at a time (a load that cannot be forwarded from those stores).
    prev2_.right = prev_.right;
    prev2_.left = prev_.left;
    prev_.right = s.control->torques.right;
    prev_.left = s.control->torques.left;
    ++count_;
    last_cross_track = std::fabs(e);
    if (s.t >= settle_time) worst_cross_track = std::max(worst_cross_track, last_cross_track);
  }

 private:
  std::int64_t count_ = 0, until_series_ = 0;
  WheelTorques prev_, prev2_;
};

struct RunResult {
  std::array<AxisMetrics, AXIS_COUNT> metrics{};
  State final_state = State::Zero();
  bool diverged = false;     ///< state became non-finite; metrics are then +inf
  bool stopped = false;      ///< ended early by the caller's stop(): the integrals so far (a lower bound)
  std::int64_t periods = 0;  ///< control periods simulated
  std::int64_t saturated_steps = 0;
};

/// The plant's state at the start of every closed loop: at rest at scenario.start.
inline State startState(const Scenario& sc) {
  State x0 = State::Zero();
  x0[X] = sc.start.x;
  x0[Y] = sc.start.y;
  x0[THETA] = sc.start.theta;
  return x0;
}
/// The plant's clock at the start: the disturbance's phase as a time (0 without one).
inline double phaseStartTime(const Scenario& sc) {
  return sc.disturbance_phase != 0.0 && sc.disturbance.frequency > 0.0 ? sc.disturbance_phase / sc.disturbance.frequency
                                                                       : 0.0;
}
/// The loops' divergence test: std::isfinite(s.sum()) with the additions of Eigen's SSE2 reduction of the
/// 7-vector, in its order (lanes {4, 2, 0} and {5, 3, 1}, then the two lanes, then 6: a sum that overflows
/// does so at the same step), from 8-byte loads: Eigen's 16-byte loads of a state that the plant's step
/// has just written 8 bytes at a time cannot be forwarded from those stores and waited for them in every
/// period (perf annotate).
inline bool finiteSum(const State& s) {
  const double even = (s[4] + s[2]) + s[0], odd = (s[5] + s[3]) + s[1];
  return std::isfinite((even + odd) + s[6]);
}

/// The end of every closed loop: the final state and the metrics into the result; a diverged run's
/// integrals are +inf (the divergence is reported, never hidden).
inline void closeRun(RunResult& result, const State& final_state, const MetricsAccumulator& metrics) {
  result.final_state = final_state;
  result.metrics = metrics.result();
  if (result.diverged) {
    const double inf = std::numeric_limits<double>::infinity();
    for (auto& m : result.metrics) m.ise = m.itse = m.iae = m.itae = inf;
  }
}

/// Asked every kStopCheckEvery periods with the metrics so far; true ends the run there. Every integral
/// only grows with time, so a caller that only needs to know whether a run beats a bound can stop once
/// the partial cost has reached it (the PSO tuner does).
using RunStop = std::function<bool(const MetricsAccumulator&)>;
constexpr std::int64_t kStopCheckEvery = 256;

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

/// The scenario's outer / inner controller behind the run-time interfaces. Throws std::invalid_argument
/// when its parameters do not validate.
std::unique_ptr<OuterController> makeOuterController(const Scenario& scenario);
std::unique_ptr<InnerController> makeInnerController(const Scenario& scenario);

/// World-frame errors (reference minus actual, theta wrapped).
inline void worldErrors(const Reference& r, const Pose2D& a, double& ex, double& ey, double& eth) {
  ex = r.pose.x - a.x;
  ey = r.pose.y - a.y;
  eth = wrapAngle(r.pose.theta - a.theta);
}

}  // namespace core
}  // namespace sowing_robot
