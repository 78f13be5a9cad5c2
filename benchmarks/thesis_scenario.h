// A hand copy of the closed loop's body (without the standstill hold, command limiter and traction layers),
// kept only for core_bench's BM_HandCopyRun25s: the real loop measured against it before the copy goes.
#pragma once

#include <vector>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/planning/potential_field.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {
namespace bench {

/// The body of runClosedLoop's loop, with its state carried from one call to the next (restarts after
/// the scenario's last step so the trajectory stays the thesis one however many steps are run).
class ControlLoop {
 public:
  ControlLoop(const core::Scenario& sc, core::ReferenceSource& reference)
      : sc_(sc),
        reference_(reference),
        plant_(sc.robot, sc.disturbance),
        kanayama_(sc.kanayama),
        smc_(sc.sliding, sc.robot),
        metrics_(false),
        n_(sc.steps()),
        dt_(core::secondsFromNanos(sc.control_period_ns)) {
    restart();
  }

  void restart() {
    core::State x0 = core::State::Zero();
    x0[core::X] = sc_.start.x;
    x0[core::Y] = sc_.start.y;
    x0[core::THETA] = sc_.start.theta;
    plant_.reset(x0, 0.0);
    smc_.reset();
    reference_.reset();
    metrics_.reset();
    k_ = 0;
  }

  /// One control period: reference, Kanayama, sliding-mode controller, plant step (as runClosedLoop).
  void step() {
    if (k_ >= n_) restart();
    const double t = core::secondsFromNanos(k_ * sc_.control_period_ns);
    const core::State& s = plant_.state();
    const core::Pose2D pose{s[core::X], s[core::Y], core::yawThroughQuaternion(s[core::THETA])};
    const core::Reference ref = reference_.next(t);
    double ex, ey, eth;
    core::worldErrors(ref, pose, ex, ey, eth);
    metrics_.add(t, ex, ey, eth);
    const core::VelocityCommand cmd = kanayama_.compute(ref, pose, s[core::V], s[core::OMEGA]);
    const core::SlidingModeOutput u = smc_.update(cmd, s[core::V], s[core::OMEGA], dt_);
    saturated_ += u.saturated ? 1 : 0;
    plant_.step(u.torques.right, u.torques.left, dt_);
    ++k_;
  }

  const core::Plant& plant() const { return plant_; }
  std::int64_t saturated() const { return saturated_; }

 private:
  core::Scenario sc_;
  core::ReferenceSource& reference_;
  core::Plant plant_;
  core::Kanayama kanayama_;
  core::SlidingModeController smc_;
  core::MetricsAccumulator metrics_;
  std::int64_t n_, k_ = 0, saturated_ = 0;
  double dt_;
};

}  // namespace bench
}  // namespace sowing_robot
