#include "sowing_robot/core/estimation/fix_await.h"

namespace sowing_robot {
namespace core {
namespace {
constexpr double kStampTolerance = 1e-6;  // [s] as FixQueue's (core/estimation/ekf.h): fixes are stamped on plant steps
}  // namespace

FixAwait::FixAwait(const FixParams& fix, double delay) : schedule_(fix), delay_(delay) { schedule_.reset(0.0); }

void FixAwait::step(double t, bool first) {
  const bool measured = schedule_.sample(t);
  // A restarted estimator's first step catches the schedule up: that slot was not measured at t.
  if (!measured || (first && t > kStampTolerance) || schedule_.inDropout(t)) return;
  if (any_received_ && t <= received_up_to_ + kStampTolerance) return;  // it came before its step
  awaited_.push_back(t);
}

void FixAwait::received(double stamp) {
  if (!any_received_ || stamp > received_up_to_) received_up_to_ = stamp;
  any_received_ = true;
  while (!awaited_.empty() && awaited_.front() <= received_up_to_ + kStampTolerance) awaited_.pop_front();
}

bool FixAwait::dueBy(double stamp, double t) const { return stamp + delay_ <= t + kStampTolerance; }

bool FixAwait::waiting(double t, double& stamp) const {
  if (awaited_.empty() || !dueBy(awaited_.front(), t)) return false;
  stamp = awaited_.front();
  return true;
}

int FixAwait::giveUp(double t) {
  int n = 0;
  for (; !awaited_.empty() && dueBy(awaited_.front(), t); ++n) awaited_.pop_front();
  return n;
}

}  // namespace core
}  // namespace sowing_robot
