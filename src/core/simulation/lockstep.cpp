#include "sowing_robot/core/simulation/lockstep.h"

#include <cmath>

namespace sowing_robot {
namespace core {

LockstepProtocol::LockstepProtocol(std::int64_t period_ns, std::int64_t last_step, const LockstepTiming& timing)
    : period_ns_(period_ns), last_step_(last_step), timing_(timing) {}

LockstepProtocol::Answer LockstepProtocol::onTorque(std::int64_t stamp_ns, const WheelTorques& torque) {
  if (!std::isfinite(torque.right) || !std::isfinite(torque.left)) {
    ++non_finite_;
    return Answer::kNonFinite;
  }
  if (phase_ != Phase::kRunning && phase_ != Phase::kFinished) return Answer::kNotRunning;
  const std::int64_t awaited_stamp = stampOf(awaited_);
  if (phase_ == Phase::kFinished) {  // every answer has been used; the final one may come again
    if (stamp_ns == awaited_stamp) {
      ++repeats_;
      return Answer::kRepeat;
    }
    return Answer::kNotRunning;
  }
  if (stamp_ns > awaited_stamp) return Answer::kAhead;
  if (stamp_ns < awaited_stamp) {
    // The answer to the state before, again: a re-sent state answered twice (both answers came).
    if (awaited_ > 0 && stamp_ns == stampOf(awaited_ - 1)) {
      ++repeats_;
      return Answer::kRepeat;
    }
    ++late_;
    return Answer::kLate;
  }
  if (awaited_ == last_step_) {
    phase_ = Phase::kFinished;
    return Answer::kFinish;
  }
  torque_ = torque;
  ++awaited_;
  return Answer::kStep;
}

void LockstepProtocol::diverged() { phase_ = Phase::kDiverged; }

LockstepProtocol::Supervision LockstepProtocol::tick(double now, bool loop_connected) {
  if (!ticked_) {
    ticked_ = true;
    wait_start_ = last_report_ = now;
  }
  switch (phase_) {
    case Phase::kConnecting:
    case Phase::kSettling: return connecting(now, loop_connected);
    case Phase::kRunning: return running(now);
    default: return {};
  }
}

LockstepProtocol::Supervision LockstepProtocol::connecting(double now, bool loop_connected) {
  Supervision s;
  if (phase_ == Phase::kConnecting && loop_connected) {
    phase_ = Phase::kSettling;
    settle_until_ = now + timing_.startup_delay;
  }
  if (phase_ == Phase::kSettling) {
    // Once connected, the settling time runs out whatever happens (as the connections are not
    // watched any more): step 0 goes, and a connection lost meanwhile is what re-sends are for.
    if (now < settle_until_) return s;
    phase_ = Phase::kRunning;
    awaited_ = 0;
    started_at_ = now;
    seen_ = 0;
    wait_start_ = last_report_ = sent_ = now;
    s.start = true;
    s.step = 0;
    return s;
  }
  s.waited = now - wait_start_;
  if (timing_.give_up > 0.0 && s.waited > timing_.give_up) {
    phase_ = Phase::kGaveUp;
    s.give_up = true;
    return s;
  }
  if (now - last_report_ >= timing_.timeout) {
    s.report = true;
    last_report_ = now;
  }
  return s;
}

LockstepProtocol::Supervision LockstepProtocol::running(double now) {
  Supervision s;
  if (awaited_ != seen_) {  // a step was taken since the last look: the wait for this answer begins now
    seen_ = awaited_;
    wait_start_ = last_report_ = sent_ = now;
    return s;
  }
  s.step = awaited_;
  s.waited = now - wait_start_;
  if (timing_.give_up > 0.0 && s.waited > timing_.give_up) {
    phase_ = Phase::kGaveUp;
    s.give_up = true;
    return s;
  }
  if (now - sent_ >= timing_.retry) {
    s.resend = true;
    sent_ = now;
  }
  if (now - last_report_ >= timing_.timeout) {
    s.report = true;
    last_report_ = now;
  }
  return s;
}

}  // namespace core
}  // namespace sowing_robot
