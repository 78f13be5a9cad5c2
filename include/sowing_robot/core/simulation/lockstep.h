// The plant's side of the lockstep protocol, without ROS and without a clock: the plant publishes the
// state at t_k and steps only when the wheel torque stamped t_k has come. This class decides what each
// received torque means (step with it, or why it is ignored) and what the supervising thread must do as
// wall time passes (start, re-send the awaited state, report the wait, give up). The caller passes the
// wall time in, so every decision can be tested step by step (test/core/simulation/test_lockstep.cpp).
//
// Not thread-safe: the caller serialises onTorque() (the thread that receives torques) and tick() (the
// supervising thread), as PlantSim's lockstep driver does with one mutex.
#pragma once

#include <cmath>
#include <cstdint>

#include "sowing_robot/core/common/types.h"

namespace sowing_robot {
namespace core {

/// Wall-clock limits of the wait for an answer [s wall].
struct LockstepTiming {
  double retry = 0.5;          ///< re-send the awaited state when it has not been answered this long (> 0)
  double timeout = 5.0;        ///< report the missing answer (or the unconnected loop) this often (> 0)
  double give_up = 120.0;      ///< end the run once an answer has been missing this long; 0 = never
  double startup_delay = 0.5;  ///< after the loop has connected, before step 0 (>= 0)
};

/// Index of a lockstep run's final state: `duration` [s] on the grid of `period_ns` (states 0..last, both
/// ends stepped), -1 for duration 0 (run forever). plant_sim stops there; run_monitor expects last + 1 samples.
inline std::int64_t lockstepLastStep(double duration, std::int64_t period_ns) {
  return duration > 0.0 ? std::llround(duration * 1e9 / static_cast<double>(period_ns)) : -1;
}

class LockstepProtocol {
 public:
  enum class Phase {
    kConnecting,  ///< waiting for the loop's connections (odom subscribers, a torque publisher)
    kSettling,    ///< connected; letting the connections settle (startup_delay)
    kRunning,     ///< a state is out and its answer awaited
    kFinished,    ///< the answer for the final state has come
    kDiverged,    ///< the caller found the stepped state bad (diverged()); nothing more is stepped
    kGaveUp,      ///< an answer stayed missing longer than give_up
  };

  /// What a received wheel torque means.
  enum class Answer {
    kStep,        ///< the answer for the awaited state: step the plant with it, then publish awaited()
    kFinish,      ///< the answer for the final state: the scenario is over (nothing is stepped)
    kLate,        ///< stamped before the last answered state (a stray or restarted source): ignored, counted
    kRepeat,      ///< the answer already used, sent again (the state was re-sent): ignored, counted
    kAhead,       ///< stamped after the awaited state: not an answer to anything published; ignored
    kNonFinite,   ///< NaN or inf: never reaches the integrator; ignored, counted
    kNotRunning,  ///< before step 0, or after a divergence or the give-up: ignored
  };

  /// What the supervising thread must do after a tick(); several may be asked at once.
  struct Supervision {
    bool start = false;      ///< publish state 0 now; from here on the answers drive the steps
    bool resend = false;     ///< re-publish the awaited state (a lost message, or a late subscriber)
    bool report = false;     ///< report the wait: before step 0 the unconnected loop, after it a stall
    bool give_up = false;    ///< end the run: waited `waited` s, longer than give_up (the phase is now kGaveUp)
    std::int64_t step = -1;  ///< the awaited state (-1 before step 0)
    double waited = 0.0;     ///< [s wall] how long it has been waited for (report, give_up)
  };

  /// period_ns: the control period (state k is stamped k * period_ns); last_step: index of the final
  /// state, -1 to run forever.
  LockstepProtocol(std::int64_t period_ns, std::int64_t last_step, const LockstepTiming& timing);

  /// A torque stamped `stamp_ns` has come. kStep advances awaited() to the next state.
  Answer onTorque(std::int64_t stamp_ns, const WheelTorques& torque);
  /// The last torque accepted with kStep.
  const WheelTorques& torque() const { return torque_; }

  /// The caller stepped with the torque and the state went bad: stop (no more steps, no re-sends).
  void diverged();

  /// The supervising thread looks at the wall clock (`wall_now`, any monotonic origin). `loop_connected`
  /// matters before step 0 only: the states have subscribers and a torque source exists.
  Supervision tick(double wall_now, bool loop_connected);

  Phase phase() const { return phase_; }
  /// Finished, diverged or gave up: the run is over and nothing more will be stepped.
  bool over() const { return phase_ == Phase::kFinished || phase_ == Phase::kDiverged || phase_ == Phase::kGaveUp; }
  /// Index of the state whose answer is awaited (the last one published); -1 before step 0.
  std::int64_t awaited() const { return awaited_; }
  std::int64_t stampOf(std::int64_t k) const { return k * period_ns_; }
  std::int64_t lastStep() const { return last_step_; }
  /// [s wall] when step 0 was started (the tick that asked for it).
  double startedAt() const { return started_at_; }
  long late() const { return late_; }
  long repeats() const { return repeats_; }
  long nonFinite() const { return non_finite_; }

 private:
  Supervision connecting(double now, bool loop_connected);
  Supervision running(double now);

  std::int64_t period_ns_;
  std::int64_t last_step_;
  LockstepTiming timing_;
  Phase phase_ = Phase::kConnecting;
  std::int64_t awaited_ = -1;
  WheelTorques torque_;
  long late_ = 0, repeats_ = 0, non_finite_ = 0;

  // Supervision clocks [s wall].
  bool ticked_ = false;
  double wait_start_ = 0.0;    // the first tick: when the wait for the loop (or for this answer) began
  double last_report_ = 0.0;   // the last report, or the start of the wait
  double settle_until_ = 0.0;  // kSettling: when step 0 may go
  double sent_ = 0.0;          // when the awaited state was last sent
  double started_at_ = 0.0;
  std::int64_t seen_ = -1;  // the awaited state the supervision clocks belong to
};

}  // namespace core
}  // namespace sowing_robot
