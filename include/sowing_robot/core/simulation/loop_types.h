// The closed loop's types, a floor below everything that runs it: the scenario (Scenario), what one
// period looks like to a trace (LoopSample, EstimatedSample), the per-period tally (RunTally), what a run
// returns (RunResult, LoopResult), and what the loop adds to a scenario beyond the controllers
// (LoopConfig: the plant, the sensors and the feedback source). closed_loop.h (the loop body),
// runner.h (its entry point) and every caller include this header; it includes
// nothing of theirs.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/control/command_limits.h"
#include "sowing_robot/core/control/controller_factory.h"
#include "sowing_robot/core/control/hitch_control.h"
#include "sowing_robot/core/control/standstill_hold.h"
#include "sowing_robot/core/control/traction_control.h"
#include "sowing_robot/core/control/traction_monitor.h"
#include "sowing_robot/core/estimation/ekf.h"
#include "sowing_robot/core/model/motor.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/model/sensors.h"
#include "sowing_robot/core/model/soil_map.h"
#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/planning/seeding.h"
#include "sowing_robot/core/planning/speed_governor.h"
#include "sowing_robot/core/simulation/metrics.h"

namespace sowing_robot {
namespace core {

/// A closed-loop run: its controller pair and their parameters (ControllerPair: outer, inner, kanayama,
/// sliding, pure_pursuit, pid; controller_factory.h), the robot, the disturbance, the timing and the start.
struct Scenario : ControllerPair {
  double duration = 25.0;                    ///< simulated time [s]
  std::int64_t control_period_ns = 1000000;  ///< plant step and control period [ns] (1 kHz)
  Pose2D start{-1.0, 0.0, 0.0};              ///< initial posture of the axle midpoint
  RobotParams robot;                         ///< nominal parameters (the controllers' model)
  PlantDisturbance disturbance;              ///< what the plant adds (disturbance, noise, mismatch)
  /// Phase of the sinusoidal disturbance [rad]: the plant's clock starts at phase / frequency (the
  /// disturbance is its only user). 0: the thesis's (and the nodes') zero phase.
  double disturbance_phase = 0.0;
  StandstillHoldParams hold;  ///< the brake at a stop in the plan (closed_loop.h, step 4)

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

/// World-frame errors (reference minus actual, theta wrapped).
inline void worldErrors(const Reference& r, const Pose2D& a, double& ex, double& ey, double& eth) {
  ex = r.pose.x - a.x;
  ey = r.pose.y - a.y;
  eth = wrapAngle(r.pose.theta - a.theta);
}

/// What the controllers close the loop on (sim.launch feedback:=).
enum class Feedback { ground_truth, odometry, fused };
/// "ground_truth", "odometry", "fused".
const char* feedbackName(Feedback f);
/// Parses a name; "" on success, else one line naming the allowed ones.
std::string parseFeedback(const std::string& name, Feedback& out);

/// Everything the estimated loop adds to a Scenario.
struct LoopConfig {
  Feedback feedback = Feedback::ground_truth;
  /// Set: the traction plant with these parameters (its `enabled` is not looked at); unset: the no-slip Plant.
  std::optional<TractionParams> traction;
  std::vector<SoilPatch> patches;    ///< traction only
  Eigen::Vector2d tool{-0.45, 0.0};  ///< the tool point in base_link (the URDF's tool_link) [m]
  /// The rows the plant's tool rule (tool_engagement.h) lowers the tool on while traction->draft_force > 0.
  std::vector<RowSegment> tool_rows;
  bool tool_rows_open_ended = false;
  SeedingParams seeding;  ///< the tool rule's parameters (detour_margin as config/seed_drill.yaml: 4 m)
  SensorParams sensors;   ///< sensors.yaml defaults
  EkfParams estimator;    ///< estimator.yaml defaults (feedback fused)
  MotorParams motor;      ///< the drive motors (off: the commanded torque reaches the wheel)
  /// Bounds on the outer loop's command, kinematic_controller's limits/ (off: the command as computed).
  CommandLimitsParams limits;
  /// Between the inner loop and the motors: each wheel's torque capped while it slips (off: unchanged).
  TractionControlParams traction_control;
  /// The target slowed along its path while a wheel slips (needs traction_control; off: planned timing).
  SpeedGovernorParams speed_governor;
  /// The tool raised while the traction control holds the wheels at their grip limit (needs
  /// traction_control; off: the seed drill's rule alone); with depth_control the drill first runs shallower
  /// within the agronomic band (seeding.depth_min..depth_max, which its depths must lie in).
  HitchControlParams hitch_control;
  /// With the speed governor: the run gets back the time the governor took from the path, i.e. it lasts
  /// until the governed path time has run the scenario's duration (at most twice the duration), so that a
  /// robot slowed for grip is judged at the same point of its path as one that was not. The benchmark's
  /// field runs set it (their finish check reads the path's time); false: the scenario's duration.
  bool governed_time_back = false;

  /// "" or the first bad parameter as one line naming its key.
  std::string validate() const;
};

struct LoopLayers;  // closed_loop.h

/// One period as the estimated loop sees it: the LoopSample on the truth (errors against the truth), and
/// what the controllers were fed.
struct EstimatedSample {
  const LoopSample* loop;
  Pose2D fed;               ///< the pose the controllers got (truth, odometry or estimate), yaw through the quaternion
  double fed_v, fed_omega;  ///< the twist they got
  double slip_right = 0.0, slip_left = 0.0;  ///< traction: the wheels' slip ratios at this state
  bool tool_down = false;                    ///< traction with a draft: the tool is down over the next step
  WheelTorques sent;                         ///< the torques sent to the motors (after the layers) [N·m]
  /// The loop's layers this period (their state after it: ceilings, slip estimates, the governor's rate).
  const LoopLayers* layers = nullptr;
  /// The seed drill's depth over the next step [m]: 0 with the tool up; with it down the depth control's
  /// (hitch_control/depth_control), else the drill's nominal (traction/draft_depth).
  double tool_depth = 0.0;
};

struct LoopResult {
  RunResult run;              ///< metrics on the truth
  double max_abs_slip = 0.0;  ///< traction: largest |slip ratio| of either wheel after a step
  /// Traction: time either wheel's |slip ratio| was above twice the friction peak's (traction/slip_peak) [s].
  double high_slip_time = 0.0;
  double tool_down_time = 0.0;  ///< traction with a draft: time the tool was down [s]
  /// Position error of the fed pose against the truth over the periods run [m] (0 for ground_truth).
  double fed_error_rms = 0.0, fed_error_max = 0.0;
  /// Heading error of the fed pose [rad], largest |.| over the run.
  double fed_heading_error_max = 0.0;
  /// Position error of the encoder odometry alone [m] at the end and its largest (any feedback).
  double odometry_error_final = 0.0, odometry_error_max = 0.0;
  FixCounts fixes;  ///< fused: what happened to the fixes
  long fixes_lost_from_queue = 0;
  double traction_control_time = 0.0;  ///< time a wheel slipped beyond the traction control's target [s]
  double governor_min_rate = 1.0;      ///< the slowest rate the speed governor gave the target
  /// Hitch control: the tool point's travel while the seed drill's rule had the tool down but the hitch
  /// held it up, i.e. the length of row left unsown [m]; and how often it raised the tool.
  double unsown_distance = 0.0;
  int hitch_raises = 0;
  /// The tool point's travel with the tool down where the seed drill sows (the reference's tool_down) [m], and the
  /// integral of the drill's depth over it [m²]: their ratio is the mean sowing depth (meanSowingDepth()).
  double sown_distance = 0.0, sown_depth_integral = 0.0;
  double meanSowingDepth() const { return sown_distance > 0.0 ? sown_depth_integral / sown_distance : 0.0; }
  /// With the traction control: the robot found without traction (the run then ended
  /// traction_control/no_traction_hold after the verdict, the robot held at rest).
  NoTractionReport no_traction;
};

}  // namespace core
}  // namespace sowing_robot
