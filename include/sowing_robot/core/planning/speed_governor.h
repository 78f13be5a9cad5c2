// A speed governor for any time-parameterised reference: the target moves along its path at a rate
// s in [min_rate, 1] of its own speed, s falling while the wheels slip (the traction control says so) and
// rising back once they grip, so that a robot that cannot hold the planned speed is not left ever
// further behind a target it cannot follow. The path is unchanged, only its timing: the wrapped source
// is asked for its reference at the governed time tau (tau' = s), and its velocities are scaled by s,
// its accelerations by s^2 (the s' terms are left out: s changes slowly against the loop). The seed
// drill spaces its seeds by distance, so slowing down does not change where they fall.
#pragma once

#include <memory>
#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/reference.h"

namespace sowing_robot {
namespace core {

/// Defaults, ranges, units and meanings: speedGovernorTable().
struct SpeedGovernorParams {
  SpeedGovernorParams();
  bool enabled;      ///< false: the reference's own timing
  double min_rate;   ///< the slowest rate s of the target
  double slow_down;  ///< [1/s] fall of s while a wheel slips
  double speed_up;   ///< [1/s] rise of s while they grip
  /// Slow down also while the traction control holds a wheel's torque below the command (its grip
  /// verdict), not only while a wheel slips beyond its target.
  bool on_grip_limit;

  std::string validate() const;
};
/// speed_governor/{enabled, min_rate, slow_down, speed_up, on_grip_limit}.
const ParamTable<SpeedGovernorParams>& speedGovernorTable();

/// `source` at the governed time.
class GovernedReference : public ReferenceSource {
 public:
  /// `source` is the caller's and must outlive this. Throws std::invalid_argument when the parameters do
  /// not validate.
  GovernedReference(ReferenceSource& source, const SpeedGovernorParams& params);
  /// The same over a source of its own (clone()).
  GovernedReference(std::unique_ptr<ReferenceSource> source, const SpeedGovernorParams& params);
  /// This period's verdicts of the traction control, for the next reference: a wheel slipped beyond
  /// its target; a wheel's command was cut to its ceiling (counted only with on_grip_limit).
  void report(bool slipping, bool grip_limited, double dt);
  void report(bool slipping, double dt) { report(slipping, false, dt); }
  double rate() const { return rate_; }
  /// The wrapped source's time [s].
  double governedTime() const { return tau_; }
  ReferenceSource& source() { return *source_; }
  std::unique_ptr<ReferenceSource> clone() const override;

 protected:
  void restart() override;
  Reference evaluate(double t) override;

 private:
  std::unique_ptr<ReferenceSource> owned_;  // set when the source is this object's own
  ReferenceSource* source_;
  SpeedGovernorParams params_;
  double rate_ = 1.0, tau_ = 0.0, last_t_ = 0.0;
  bool started_ = false;
};

}  // namespace core
}  // namespace sowing_robot
