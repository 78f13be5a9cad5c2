// The one closed loop of the core: a plant, a feedback source, an outer and an inner controller and a
// reference, stepped period by period in the order the node pipeline steps them in lockstep, so that
// the in-process runs and the nodes give the same numbers. Every in-process run goes through it:
// runClosedLoop (runner.h: the no-slip plant fed its own state, or with a LoopConfig either plant, fed the
// state, the encoders or the EKF), and through it the benchmark, the tuner, the field runs and the Python
// module. Its types are loop_types.h's, its feedback sources sensor_feeds.h's;
// it includes none of its callers.
//
// Period k, t_k = k * period (secondsFromNanos, as ros::Time::toSec):
//   1. the state; a non-finite one ends the run as diverged;
//   2. the feedback source gives the pose (through the quaternion round trip of nav_msgs/Odometry) and
//      twist the controllers get;
//   3. the reference at t_k; the errors against the TRUE pose go into the metrics;
//   4. outer controller -> velocity command, inner controller -> wheel torques; at a stop hold (the
//      reference's stop: the inner loop frozen) the standstill hold brakes on the fed twist instead; the traction
//      control (if on) caps the torque of a slipping wheel, and tells the speed governor (if on) for the next period;
//   5. with the traction plant and a draft: the tool rule on the true tool point lowers or lifts the tool, the
//      hitch control (if on) holds it up or, with depth control, sets the drill's depth for the step;
//      With the traction control, its progress check (traction_monitor.h) may find the robot without
//      traction: from the next period on the robot is held (a stop hold whatever the reference), and
//      the run ends traction_control/no_traction_hold later;
//   6. the trace sees the period; the caller's stop() may end the run here (every kStopCheckEvery);
//   7. the plant steps (k < n; n grows by the time a speed governor took, with governed_time_back; its motors,
//      if on, between the torques sent and the wheels), then the sensors see the new state at t_{k+1}.
//
// The parts are template parameters, so the per-period calls are direct:
//   Plant: NoSlipPlant or SlipPlant (below); Feed: StateFeed (the plant's state, no sensors) or the
//   sensors with the fed pose chosen at run time (SensorFeed; both in sensor_feeds.h); Outer/Inner: the concrete
//   controllers or the run-time interfaces of controllers.h; Trace: an empty std::function, a std::function of
//   LoopSample or EstimatedSample, or a RunTally (its add() inlined, and what it does not read never built).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>

#include "sowing_robot/core/control/command_limits.h"
#include "sowing_robot/core/control/hitch_control.h"
#include "sowing_robot/core/control/standstill_hold.h"
#include "sowing_robot/core/control/traction_control.h"
#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/planning/speed_governor.h"
#include "sowing_robot/core/planning/tool_engagement.h"
#include "sowing_robot/core/simulation/loop_types.h"
#include "sowing_robot/core/simulation/sensor_feeds.h"

namespace sowing_robot {
namespace core {

/// The no-slip Plant behind the loop's plant interface.
struct NoSlipPlant {
  static constexpr bool kTraction = false;
  Plant plant;
  void reset(const State& x0, double t0) { plant.reset(x0, t0); }
  void step(double r, double l, double dt) { plant.step(r, l, dt); }
  const State& state() const { return plant.state(); }
  double slip(Wheel) const { return 0.0; }
  /// R W of the wheel [m/s]: rolling, the contact point's speed.
  double wheelSpeed(Wheel w) const {
    const State& s = plant.state();
    return w == RIGHT ? s[V] + L * s[OMEGA] : s[V] - L * s[OMEGA];
  }
  void setToolDown(bool) {}
  void setToolDepth(double) {}
  double toolDepth() const { return 0.0; }
  double L;  ///< the plant's half track [m]
};

/// The wheel–soil TractionPlant behind the same interface.
struct SlipPlant {
  static constexpr bool kTraction = true;
  TractionPlant plant;
  void reset(const State& x0, double t0) { plant.reset(x0, t0); }
  void step(double r, double l, double dt) { plant.step(r, l, dt); }
  const State& state() const { return plant.state(); }
  double slip(Wheel w) const { return plant.slipRatio(w); }
  double wheelSpeed(Wheel w) const { return R * plant.wheelRate(w); }
  void setToolDown(bool down) { plant.setToolDown(down); }
  void setToolDepth(double depth) { plant.setToolDepth(depth); }
  double toolDepth() const { return plant.toolDepth(); }
  double R;  ///< the plant's wheel radius [m]
};

/// The tool rule of the traction plant with a draft (tool_engagement.h), on the true tool point.
struct ToolRule {
  bool active;           ///< the traction plant with draft_force > 0
  Eigen::Vector2d tool;  ///< the tool point in base_link [m]
  ToolEngagement rule;
  /// The tool point's speed over ground at state s [m/s] (rigid body: v - w yt along, w xt across).
  double speed(const State& s) const { return std::hypot(s[V] - s[OMEGA] * tool.y(), s[OMEGA] * tool.x()); }
  /// Lowered (true) or lifted for the step from state s.
  bool update(const State& s) {
    const double sn = std::sin(s[THETA]), c = std::cos(s[THETA]);
    return rule.update({s[X] + c * tool.x() - sn * tool.y(), s[Y] + sn * tool.x() + c * tool.y()});
  }
};

/// The loop's optional layers (null: off).
struct LoopLayers {
  ToolRule* tool = nullptr;                     ///< the traction plant's tool rule
  CommandLimiter* limiter = nullptr;            ///< between the outer and the inner loop
  TractionControl* traction_control = nullptr;  ///< between the inner loop and the motors
  GovernedReference* governor = nullptr;        ///< the reference the loop is given, governed
  HitchControl* hitch = nullptr;                ///< raises the tool (or first runs it shallower) on the grip verdict
  TractionMonitor* monitor = nullptr;           ///< the traction control's progress check (needs it)
  /// With the governor: the run lasts until the governed time has run the scenario's duration, at most twice
  /// its duration (LoopConfig::governed_time_back).
  bool governed_time_back = false;
  /// Traction plant: a period after which either wheel's |slip ratio| exceeds this counts to high_slip_time.
  double high_slip = std::numeric_limits<double>::infinity();
  /// The standstill hold closes its along axis on the wheels' own rates (the encoders', Fed::speeds) instead of the
  /// fed speed, and the traction control does not cap it: fed the EKF with the traction control on (the estimate's
  /// noise is beyond what the stiff brake can hold on; standstill_hold.h, docs/stops.md).
  bool hold_on_wheels = false;
};

namespace loop_detail {

// Whether the trace is to see this period (a RunTally always; a std::function when set), and the period
// handed to it: LoopSample, or EstimatedSample with what the controllers were fed.
inline bool wants(const RunTally&) { return true; }
template <typename Sample>
bool wants(const std::function<void(const Sample&)>& trace) {
  return static_cast<bool>(trace);
}
inline void emit(const std::function<void(const LoopSample&)>& trace, const LoopSample& s, const Fed&, double, double,
                 bool, double, const WheelTorques&, const LoopLayers&) {
  trace(s);
}
inline void emit(const std::function<void(const EstimatedSample&)>& trace, const LoopSample& s, const Fed& fed,
                 double slip_r, double slip_l, bool tool_down, double tool_depth, const WheelTorques& sent,
                 const LoopLayers& layers) {
  trace({&s, fed.pose, fed.v, fed.omega, slip_r, slip_l, tool_down, sent, &layers, tool_depth});
}
inline void emit(RunTally& tally, const LoopSample& s, const Fed&, double, double, bool, double, const WheelTorques&,
                 const LoopLayers&) {
  tally.add(s);
}

}  // namespace loop_detail

/// Runs scenario `sc` (its timing, start, disturbance phase) on `plant` (constructed, not yet reset) with
/// the given feedback, controllers and reference; see the file comment for the order of a period.
template <typename PlantT, typename Feed, typename Outer, typename Inner, typename Trace>
LoopResult closedLoop(const Scenario& sc, PlantT& plant, Feed& feed, Outer& outer, Inner& inner,
                      ReferenceSource& reference, bool keep_samples, Trace& trace, const RunStop& stop,
                      const LoopLayers& layers = {}) {
  plant.reset(startState(sc), phaseStartTime(sc));
  reference.reset();
  feed.start(plant.state());
  if (layers.limiter) layers.limiter->reset();
  if (layers.traction_control) layers.traction_control->reset();
  if (layers.hitch) layers.hitch->reset();
  if (layers.monitor) layers.monitor->reset();
  double end_at = 0.0;  // no traction: the run ends here
  const std::int64_t n = sc.steps();
  const double dt = secondsFromNanos(sc.control_period_ns);
  MetricsAccumulator metrics(keep_samples);
  metrics.reserve(static_cast<std::size_t>(n + 1));
  LoopResult out;
  RunResult& result = out.run;
  StandstillHold hold(sc.hold, sc.robot, sc.innerMaxTorque());
  bool holding = false;

  std::int64_t last = n;  // the last period: n, or later by the time a governor took back (governed_time_back)
  for (std::int64_t k = 0; k <= last; ++k) {
    const double t = secondsFromNanos(k * sc.control_period_ns);
    const State& s = plant.state();
    if (!finiteSum(s)) {
      result.diverged = true;
      break;
    }
    const Pose2D truth{s[X], s[Y], yawThroughQuaternion(s[THETA])};
    const Fed fed = feed.observe(t, s, truth, plant.wheelSpeed(RIGHT), plant.wheelSpeed(LEFT));
    const Reference& ref = reference.next(t);  // the source's copy, valid until the next call
    double ex, ey, eth;
    worldErrors(ref, truth, ex, ey, eth);
    metrics.add(t, ex, ey, eth);
    const bool no_traction = layers.monitor != nullptr && layers.monitor->detected();
    VelocityCommand cmd = no_traction ? holdCommand() : outer.compute(ref, fed.pose, fed.v, fed.omega);
    if (layers.limiter) cmd = layers.limiter->limit(cmd, dt);
    InnerOutput u = inner.update(cmd, fed.v, fed.omega, dt);
    if (u.holding) {  // a stop: the inner loop is frozen, the brake holds the robot where it is
      if (!holding) hold.engage();
      const bool on_wheels = layers.hold_on_wheels;
      const double hold_v =
          on_wheels ? StandstillHold::wheelSpeed(fed.speeds.wheel_right, fed.speeds.wheel_left) : fed.v;
      const HoldTorques h = hold.update(hold_v, fed.omega, dt);
      u.torques = h.torques;
      u.u1 = h.u1;
      u.u2 = h.u2;
      u.saturated = h.saturated;
    }
    holding = u.holding;
    if (u.saturated) ++result.saturated_steps;
    WheelTorques sent = u.torques;
    if (TractionControl* tc = layers.traction_control) {
      sent = tc->limit(u.torques, fed.speeds, dt);
      // Held on the wheels' own counts the brake is a lock on each wheel, which keeps its grip by itself; the
      // ceiling would cut it on false slips (at rest the encoders' speed quantum against the EKF's ground speed
      // reads as a slip of about slip_target) to below the disturbance it must hold against.
      if (u.holding && layers.hold_on_wheels) sent = u.torques;
      if (tc->params().anti_windup) inner.heldBack(sent);
      if (u.holding) hold.heldBack(sent);  // the brake's spring keeps only what reached the wheels (always)
      if (tc->slipping()) out.traction_control_time += dt;
      if (layers.governor) {
        layers.governor->report(tc->slipping(), tc->limiting(), dt);
        out.governor_min_rate = std::min(out.governor_min_rate, layers.governor->rate());
        if (layers.governed_time_back) {  // the path time lost so far, in whole periods (it never shrinks)
          const double lost = t - layers.governor->governedTime();
          last = std::min(2 * n, n + static_cast<std::int64_t>(std::ceil(lost / dt - 1e-9)));
        }
      }
      if (layers.monitor && !no_traction && layers.monitor->update(t, fed.pose, !cmd.hold, tc->slippingAsFed(), dt)) {
        out.no_traction = layers.monitor->report();
        end_at = t + tc->params().no_traction_hold;
      }
    }
    bool tool_down = false;
    double tool_depth = 0.0;  // [m] 0 with the tool up
    if constexpr (PlantT::kTraction) {
      ToolRule* tool = layers.tool;
      if (tool != nullptr && tool->active && k < last) {
        tool_down = tool->update(s);
        if (HitchControl* hitch = layers.hitch) {
          const bool raised = hitch->update(layers.traction_control->limiting(), std::fabs(fed.v) * dt, dt);
          // Depth control: the drill at the hitch's depth from this step on (without it, the plant's nominal).
          if (hitch->controlsDepth()) plant.setToolDepth(hitch->depth());
          if (tool_down && raised) {
            tool_down = false;
            // Where the seed drill would sow (the reference's tool_down too), the row goes unsown.
            if (ref.tool_down) out.unsown_distance += tool->speed(s) * dt;
          }
        }
        plant.setToolDown(tool_down);
        if (tool_down) {
          out.tool_down_time += dt;
          tool_depth = plant.toolDepth();
          if (ref.tool_down) {
            out.sown_distance += tool->speed(s) * dt;
            out.sown_depth_integral += tool_depth * tool->speed(s) * dt;
          }
        }
      }
    }
    if (loop_detail::wants(trace))
      loop_detail::emit(trace, {t, &s, &ref, &cmd, &u, inner.m0Hat(), inner.i0Hat(), ex, ey, eth}, fed,
                        plant.slip(RIGHT), plant.slip(LEFT), tool_down, tool_depth, sent, layers);
    result.periods = k;
    if (no_traction && t >= end_at) break;  // held since the verdict: the run ends with its report
    if (stop && k % kStopCheckEvery == kStopCheckEvery - 1 && k < last && stop(metrics)) {
      result.stopped = true;
      break;
    }
    if (k == last) break;
    plant.step(sent.right, sent.left, dt);
    if constexpr (PlantT::kTraction) {
      const double slip = std::max(std::fabs(plant.slip(RIGHT)), std::fabs(plant.slip(LEFT)));
      out.max_abs_slip = std::max(out.max_abs_slip, slip);
      if (slip > layers.high_slip) out.high_slip_time += dt;
    }
    feed.afterStep(k + 1, plant.state());
  }
  closeRun(result, plant.state(), metrics);
  feed.finish(out);
  return out;
}

}  // namespace core
}  // namespace sowing_robot
