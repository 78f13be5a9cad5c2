// Lockstep: which position fixes an estimator step must hold before it runs. The plant publishes a fix
// at stamp + latency on a connection of its own, and the estimator applies it once the estimate is
// stamp + delay; with nothing else ordering the two, a busy core could let the estimate pass that time
// first (the fix then lands a step later, and the run differs). The estimator keeps the plant's fix
// schedule and holds a step until every fix due by it has come.
#pragma once

#include <deque>

#include "sowing_robot/core/model/sensors.h"

namespace sowing_robot {
namespace core {

class FixAwait {
 public:
  /// `fix`: the plant's fix keys (rate, dropout); `delay`: the estimator's estimator/fix/delay [s].
  FixAwait(const FixParams& fix, double delay);
  /// Every step once, t increasing [s]. `first`: the estimator's first step; a first step after t = 0
  /// (a restarted estimator) awaits nothing measured before it.
  void step(double t, bool first);
  /// A fix stamped `stamp` [s] has come (fixes come in stamp order, but may come before the step that
  /// measured them is seen here).
  void received(double stamp);
  /// The step at t must wait: a fix due by it (stamp + delay <= t) has not come; `stamp` gets its stamp.
  bool waiting(double t, double& stamp) const;
  /// Stop waiting for the fixes due by t (lost: the plant asked for the step again); returns how many.
  int giveUp(double t);

 private:
  bool dueBy(double stamp, double t) const;

  FixSchedule schedule_;
  double delay_;
  bool any_received_ = false;
  double received_up_to_ = 0.0;
  std::deque<double> awaited_;  // stamps measured, outside the dropout, not yet received; oldest first
};

}  // namespace core
}  // namespace sowing_robot
