#include "sowing_robot/core/planning/speed_governor.h"

#include <algorithm>
#include <stdexcept>

namespace sowing_robot {
namespace core {

const ParamTable<SpeedGovernorParams>& speedGovernorTable() {
  using P = SpeedGovernorParams;
  static const ParamTable<P> table({
      flag("speed_governor/enabled", &P::enabled, false,
           "slow the target along its path while the wheels slip; false: the reference's own timing"),
      number("speed_governor/min_rate", &P::min_rate, 0.2, Limits::above(0.0, 1.0), "",
             "the slowest the target moves, as a share of its planned speed"),
      number("speed_governor/slow_down", &P::slow_down, 1.0, Limits::positive(), "1/s",
             "fall of the rate while a wheel slips"),
      number("speed_governor/speed_up", &P::speed_up, 0.2, Limits::positive(), "1/s",
             "rise of the rate while the wheels grip"),
      flag("speed_governor/on_grip_limit", &P::on_grip_limit, false,
           "slow down also while the traction control holds a wheel's torque below the command (the wheels at "
           "their grip limit); false: only while a wheel slips beyond the traction control's target"),
  });
  return table;
}

SpeedGovernorParams::SpeedGovernorParams() { speedGovernorTable().applyDefaults(*this); }

std::string SpeedGovernorParams::validate() const { return speedGovernorTable().checkRanges(*this); }

GovernedReference::GovernedReference(ReferenceSource& source, const SpeedGovernorParams& params)
    : source_(&source), params_(params) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
}

GovernedReference::GovernedReference(std::unique_ptr<ReferenceSource> source, const SpeedGovernorParams& params)
    : GovernedReference(*source, params) {
  owned_ = std::move(source);
}

void GovernedReference::report(bool slipping, bool grip_limited, double dt) {
  if (!params_.enabled) return;
  rate_ = slipping || (grip_limited && params_.on_grip_limit)
              ? std::max(params_.min_rate, rate_ - params_.slow_down * dt)
              : std::min(1.0, rate_ + params_.speed_up * dt);
}

std::unique_ptr<ReferenceSource> GovernedReference::clone() const {
  auto c = std::make_unique<GovernedReference>(source_->clone(), params_);
  c->reset();
  return c;
}

void GovernedReference::restart() {
  source_->reset();
  rate_ = 1.0;
  tau_ = last_t_ = 0.0;
  started_ = false;
}

Reference GovernedReference::evaluate(double t) {
  if (!params_.enabled) return source_->next(t);
  // The first call fixes the time origin (the loop starts at t = 0, a restarted one later).
  tau_ += started_ ? rate_ * (t - last_t_) : t;
  started_ = true;
  last_t_ = t;
  Reference r = source_->next(tau_);
  r.v *= rate_;
  r.omega *= rate_;
  r.v_dot *= rate_ * rate_;
  r.omega_dot *= rate_ * rate_;
  return r;
}

}  // namespace core
}  // namespace sowing_robot
