// Wheel-slip detection for the slip-aware EKF (ekf.h with estimator/slip/detect). The
// filter itself estimates each wheel's slip speed (slip_aware_step.h: the wheel's encoder measures the
// ground speed of its contact point plus its slip), so a slip that builds up as fast as the slip's random
// walk allows needs no detector: against the gyro, the difference of the two wheels' travels less 2L times
// the heading change measures the difference of their slips at once; against the fixes, the position
// they give measures the ground speed, and with it the common part. What a random walk cannot follow is a
// wheel breaking loose (spinning up, or locking) or gripping again within a fraction of a second; and a
// slow common slip shows in the fixes only after a while. This detector finds those:
//
//   each wheel's claim of the body's speed, its travel less the rotation the gyro measures,
//       u_R = s_R / dt - L (r - b),   u_L = s_L / dt + L (r - b),
//   smoothed by two exponential averages (time constants window / 5 and window);
//   1. a claim beyond what the ground can do: |u_i| > max_ground_speed, or changing faster than
//      max_acceleration (the soil's grip cannot accelerate the robot faster, so the change is the
//      wheel's own; the difference of the two averages over 0.8 window is the acceleration of a ramp,
//      and a step shows as a steep one). The wheel is then "loose": its encoder is left out of the steps
//      (from 4 windows before the test fired, the averages' delay) until its claim is plausible again,
//      and its slip is then re-acquired (its variance opened, so the next steps take it from the other
//      wheel, the gyro and the fixes: spinning on at a new speed or gripping, the filter cannot tell
//      which from the wheel alone). This is what sees both wheels spin up alike, which the gyro cannot;
//   2. the fixes against the encoders: a two-sided CUSUM (Page's test) of the fixes' along-track
//      innovations over their standard deviation (allowance 0.5, alarm at cusum_threshold): both wheels'
//      slips are re-opened from that fix on by what the ground speed's random walk allows over the time
//      the evidence built up (the slip may have drifted as much unseen); any fix outside the gate
//      re-acquires them fully.
//
// The detector only decides; ekf.h applies the verdicts. It is deterministic and fed in the filter's call
// order, so the node and the in-process loop get the same verdicts.
#pragma once

#include <string>

#include "sowing_robot/core/common/param_table.h"

namespace sowing_robot {
namespace core {

/// estimator/slip/... of the slip-aware filter. Defaults, ranges, units and meanings: slipParamsTable().
struct SlipParams {
  SlipParams();
  bool detect;              ///< the slip-aware filter (ground speed and slip states, this detector)
  double max_ground_speed;  ///< [m/s] no ground speed beyond this
  double max_acceleration;  ///< [m/s²] no ground acceleration beyond this (the soil's grip)
  double speed_tolerance;   ///< [m/s] a wheel whose estimated slip speed exceeds this is reported slipping
  double window;            ///< [s] time constant of the averaged claims
  double cusum_threshold;   ///< [std] the fixes' CUSUM alarm level; 0: no CUSUM
  double speed_walk;        ///< [m/s/√s] random walk of the ground speed
  double slip_walk;         ///< [m/s/√s] random walk of each wheel's slip speed
  double slip_rate;         ///< [1/√s] ... plus this times the slip speed

  /// checkRanges() with the keys as the EKF's table names them (estimator/slip/...).
  std::string validate() const;
};
/// Keys relative to estimator/slip/: detect, max_ground_speed, max_acceleration, speed_tolerance, window,
/// cusum_threshold, speed_walk, slip_walk, slip_rate.
const ParamTable<SlipParams>& slipParamsTable();

/// Wheels as bits: the right wheel 1, the left 2.
enum SlipWheel : unsigned { SLIP_NONE = 0u, SLIP_RIGHT = 1u, SLIP_LEFT = 2u, SLIP_BOTH = 3u };

/// What the detector found, counted per event.
struct SlipCounts {
  long loose = 0;     ///< a wheel broke loose or gripped again (its claim implausible), per wheel
  long by_fixes = 0;  ///< the fixes' CUSUM alarmed or a fix was outside the gate
  double time = 0.0;  ///< [s] steps with at least one wheel loose or slipping beyond speed_tolerance
};

/// One plant step as the detector sees it.
struct SlipEvidence {
  double dt = 0.0;            ///< [s]
  double travel_right = 0.0;  ///< [m] the encoders' wheel travel over the step, R dphi
  double travel_left = 0.0;   ///< [m]
  bool has_rate = false;      ///< a yaw rate for this step (else the encoders' heading change stands in)
  double rate = 0.0;          ///< [rad/s] the gyro's rate less the filter's bias estimate
};

class SlipDetector {
 public:
  /// half_track: the nominal L [m] (> 0).
  SlipDetector(const SlipParams& params, double half_track);
  /// No wheel loose, the averages restart at the next step, the CUSUM at zero.
  void reset();
  /// One step: the loose wheels over it (SlipWheel bits). `onset` gets the wheels that broke loose with
  /// this step (the filter then applies the verdict from 4 windows back).
  unsigned step(const SlipEvidence& e, unsigned& onset);
  /// A fix (stamp [s]) and its along-track innovation over its standard deviation (positive: the fix ahead
  /// of the estimate in the direction of travel). When the CUSUM alarms: how long its evidence ran [s]
  /// (from the fix before the alarming sum left zero; > 0), else 0.
  double fix(double stamp, double along);
  /// A fix outside the gate (counted).
  void gatedFix() { ++counts_.by_fixes; }
  unsigned loose() const { return loose_; }
  /// Adds dt to the time counted as slipping.
  void countSlipping(double dt) { counts_.time += dt; }
  const SlipCounts& counts() const { return counts_; }

 private:
  SlipParams params_;
  double L_;
  bool primed_ = false;
  double quick_[2] = {0.0, 0.0}, smooth_[2] = {0.0, 0.0};  // each wheel's claim averaged over window / 5, window
  unsigned loose_ = SLIP_NONE;
  double cusum_ahead_ = 0.0, cusum_behind_ = 0.0;
  double last_fix_ = 0.0, ahead_since_ = 0.0, behind_since_ = 0.0;  // stamps [s]
  SlipCounts counts_;
};

}  // namespace core
}  // namespace sowing_robot
