// State estimator for the DDMR: an extended Kalman filter over the pose of the axle
// midpoint and the gyro's bias, s = (x, y, theta, b), fed by the wheel encoders and the yaw rate, and
// corrected by a position fix that arrives late.
//
// Prediction, one plant step (duration dt):
//   the encoders give the step's distance and heading change (u_m, d_m) with a covariance C (the
//   caller's, plus the process noise of the table: distance_noise^2 |u_m| and heading_noise^2 |u_m|,
//   which stand for slip and wheel-radius errors, growing with the distance rolled). These are the
//   prior of the step's true (u, d), independent of s. C must not depend on this step's own
//   measurement error (see wheelTravelCovariance: computed from the quantised increments, it biased the
//   distance through the gyro update). The gyro's rate r is a measurement of them:
//   r dt = d + b dt + n dt (n: the rate's noise, variance per sample as sensor_msgs/Imu gives it),
//   linear in the augmented vector a = (s, d, u), so one exact Kalman update fuses both heading
//   sources and makes the bias observable (standing still, d is known to the tick and r - d/dt is b).
//   Then the motion (midpoint heading, as the encoder odometry integrates):
//     x' = x + u cos(theta + d/2),  y' = y + u sin(theta + d/2),  theta' = theta + d,  b' = b
//   with P' = F Pa F^T + Q, F = df/da (4x6), Q the bias random walk bias_walk^2 dt.
//   Why the bias is in the state: the yaw-rate sensor's bias (sensors/imu/bias) integrates into a
//   heading error that grows without bound through a fix dropout; estimated, it is cancelled, and the
//   covariance says how well. bias/estimate false pins b at 0 with zero variance (a 3-state filter).
//
// Fix update: z = (x, y) + v, v ~ N(0, R); the innovation's squared Mahalanobis distance is gated
// (gate > 0: refused above it) and the update uses the Joseph form. A fix is stamped with its
// MEASUREMENT time: the filter keeps the last history_length steps (state, covariance, the step's
// inputs and the fixes applied there), applies the fix to the newest kept state not after its stamp
// (1 us tolerance; fixes are sampled on plant steps) and propagates again from there with the kept
// inputs, re-applying the later fixes. So a late fix ends in exactly the estimate a filter would have
// had with the fix applied at its stamp (test_ekf checks it). A fix older than the history, stamped
// after the newest state, or with a non-finite or non-positive-definite value, is refused and counted.
//
// Re-anchoring (fix/reanchor_after = n > 0): once n fixes in a row were gated, the next gated fix is not
// refused but taken as the position: x, y := the fix, their covariance := the fix's, their correlation
// with heading and bias dropped (heading and bias kept: a spinning wheel corrupts the encoders'
// distance, not the gyro's heading). Why: when the wheels slip (wet soil) the encoders count distance
// the robot does not travel; the estimate leaves the truth faster than its covariance says, every
// later fix lies outside the gate, and without this the filter never comes back. Counted (reanchored).
//
// Slip (slip/inflation = k > 1): a gated fix is taken as the sign that the wheels slip; from then on every
// step's distance variance from the table (distance_noise^2 |u_m|) is k times larger, so the next fixes
// pass the gate and pull the estimate back instead of being refused, until an applied fix agrees with
// the prediction within the fix's own noise (squared distance against the fix's covariance below 1). The
// inflation is stored with the step's inputs, so a late fix re-propagates through the same steps.
// Without any gated fix nothing changes. Counted (slip_onsets).
//
// The slip-aware filter (slip/detect true; off by default, and then everything above is unchanged to the
// bit): the state gains the ground speed and each drive wheel's slip speed, each wheel's encoder measures
// its contact point's ground speed plus its slip, the gyro the heading change, the fixes the position
// (slip_aware_step.h); a detector finds a wheel breaking loose or gripping again faster than the slip's
// random walk can follow, and slow common slip from the fixes (slip_detector.h; a gated fix counts too,
// in place of slip/inflation). A loose wheel's encoder is left out, from slip/window x 4 before the test
// fired (the history is propagated again); when it is plausible again its slip is re-acquired (its
// variance opened). The verdicts are stored with the steps, so a late fix re-propagates through the same
// ones. Re-anchoring works as above. docs/slip_aware_estimator.md has the design, the bound and the recovery time.
#pragma once

#include <Eigen/Core>
#include <boost/circular_buffer.hpp>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/estimation/slip_aware_step.h"
#include "sowing_robot/core/estimation/slip_detector.h"

namespace sowing_robot {
namespace core {

/// Parameters of the estimator, under estimator/ on state_estimator's private namespace. Defaults,
/// ranges, units and meanings: ekfTable().
struct EkfParams {
  EkfParams();
  double distance_noise;       ///< [m/sqrt(m)] encoder distance error per sqrt(metre rolled)
  double heading_noise;        ///< [rad/sqrt(m)] encoder heading error per sqrt(metre rolled)
  double increment_sigma;      ///< [m] std of one wheel-travel increment from the encoders' quantisation
  double bias_walk;            ///< [rad/s/sqrt(s)] random walk of the gyro bias
  bool estimate_bias;          ///< bias in the state; false: b = 0, no variance
  double initial_sigma_xy;     ///< [m]
  double initial_sigma_theta;  ///< [rad]
  double initial_sigma_bias;   ///< [rad/s]
  int history_length;          ///< steps kept for late fixes
  double gate;                 ///< squared Mahalanobis distance above which a fix is refused; 0: no gate
  int reanchor_after;          ///< gated fixes in a row after which the next gated one re-anchors x, y; 0: never
  double slip_inflation;       ///< after a gated fix, the distance noise variance times this until fixes agree
  double fix_delay;            ///< [s] the ROS node applies a fix once its state is this much newer (determinism)
  SlipParams slip;             ///< estimator/slip/...: the slip-aware filter (slip.detect; off by default)

  /// checkRanges(): the first bad value as one line naming its key ("" when all are good).
  std::string validate() const;
};
/// estimator/{odometry/distance_noise, odometry/heading_noise, odometry/increment_sigma, bias/walk, bias/estimate,
/// initial/sigma_xy, initial/sigma_theta, initial/sigma_bias, history/length, fix/gate, fix/reanchor_after,
/// slip/inflation, fix/delay, slip/... of slipParamsTable()}.
const ParamTable<EkfParams>& ekfTable();

/// One plant step's measurements.
struct EkfStepInput {
  double distance = 0.0;  ///< [m] encoder distance of the axle midpoint over the step
  double dtheta = 0.0;    ///< [rad] encoder heading change over the step
  /// Covariance of (distance, dtheta) as the odometry states it (the table's process noise is added).
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  bool has_rate = false;       ///< a yaw rate for this step
  double rate = 0.0;           ///< [rad/s] measured yaw rate (true rate + bias + noise)
  double rate_variance = 0.0;  ///< [(rad/s)^2] of one sample
};

/// Covariance of (distance, dtheta) of one step when each wheel's travel d_i has the variance
/// variance_per_metre |d_i| (Siegwart's odometry model, as core/model/sensors.h's travel_variance states it):
/// distance = (d_r + d_l) / 2, dtheta = (d_r - d_l) / (2 half_track).
/// d_right, d_left: the wheels' travels over the step as a smoothed reading gives them, e.g. the encoders'
/// velocity window (Odometry2D: (v ± L omega) dt), NOT the step's own quantised increments. Why: at
/// 2048 ticks per turn and 0.6 m/s a wheel counts 2 or 3 ticks per 1 ms step, so |d_r| - |d_l|, the
/// off-diagonal, is ±1 tick whenever one wheel gains a tick, with the sign of that tick's error in the
/// step's dtheta, which is what the gyro update sees as its innovation; the update moves the distance by
/// cov / var times the innovation, shortening it whichever wheel gained the tick: 7.4 um per step (1.2 %
/// of the travel), the estimate 7 mm behind the truth, mean NEES 5.7 (test_ekf,
/// EkfWithSensors.NeesWithinChiSquareBounds; the window's travels give 3.8, consistent).
Eigen::Matrix2d wheelTravelCovariance(double d_right, double d_left, double half_track, double variance_per_metre);

/// Covariance of (distance, dtheta) of one step from the encoders' quantisation: each wheel's travel
/// increment has the std increment_sigma, independently: diag(s²/2, s²/(2 L²)), L = half_track.
/// Why per step although quantisation errors telescope: without it the filter takes a step's encoder
/// heading change as exact, and at a high yaw rate (the thesis start turns at ~2 rad/s) the one-tick
/// error of that change (R res / L in 1 ms, ~1 rad/s) goes into the gyro bias. Stated per step, the
/// gyro (5e-6 rad per step) carries the heading between fixes and the bias is learnt from the fixes.
/// The distance's share is conservative: nothing else measures a step's distance, its quantisation
/// errors telescope (the summed distance is within a tick of the truth), yet stated per step they add
/// up. In test_ekf's sensor runs the along-track variance is so ~10 % too large (NEES 3.8 of 4; 3.9 and
/// per state 1.0 with the distance's share 0); kept, so that the node's estimates stay as they were.
Eigen::Matrix2d encoderIncrementCovariance(double increment_sigma, double half_track);

/// A position fix of the axle midpoint, stamped with its measurement time.
struct EkfFix {
  double stamp = 0.0;  ///< [s]
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();
};

enum class FixOutcome { APPLIED, REANCHORED, REFUSED_INVALID, REFUSED_TOO_OLD, REFUSED_FUTURE, REFUSED_GATE };
const char* fixOutcomeName(FixOutcome o);

/// Counts of what happened to the fixes offered to fuse().
struct FixCounts {
  long applied = 0, invalid = 0, too_old = 0, future = 0, gated = 0;
  long reanchored = 0;   ///< gated fixes taken as the position (fix/reanchor_after); also counted in applied
  long slip_onsets = 0;  ///< times a gated fix started the slip inflation (slip/inflation)
  long refused() const { return invalid + too_old + future + gated; }
};

class Ekf {
 public:
  using Vector = Eigen::Matrix<double, 4, 1>;
  using Matrix = Eigen::Matrix<double, 4, 4>;
  enum Index { X = 0, Y = 1, THETA = 2, BIAS = 3 };

  /// Throws std::invalid_argument when the parameters do not validate, or with slip/detect when half_track
  /// (the nominal L [m], which turns the encoders' increments into the wheels' travels) is not > 0.
  explicit Ekf(const EkfParams& params, double half_track = 0.0);

  /// Start at time t from a pose (and bias) with the table's initial covariance; clears the history
  /// (the counts stay). Throws std::invalid_argument for a non-finite value.
  void reset(double t, const Pose2D& pose, double bias = 0.0);
  /// Start from a given mean and covariance (must be finite and symmetric).
  void reset(double t, const Vector& mean, const Matrix& covariance);
  bool initialised() const { return !history_.empty(); }

  /// Advance to time t (> time()) over one step's measurements. Returns false, changing nothing, for
  /// a non-finite input, a negative variance, t <= time() or before reset().
  bool predict(double t, const EkfStepInput& in);

  /// Apply a fix at its stamp (see the file comment). Counted in counts().
  FixOutcome fuse(const EkfFix& fix);

  double time() const { return history_.back().t; }
  const Vector& mean() const { return history_.back().mean; }
  const Matrix& covariance() const { return history_.back().cov; }
  Pose2D pose() const { return {mean()(X), mean()(Y), mean()(THETA)}; }
  /// Oldest stamp a fix may have to be applied (history_length steps back).
  double oldestTime() const { return history_.front().t; }
  std::size_t historySize() const { return history_.size(); }
  const FixCounts& counts() const { return counts_; }
  /// The slip inflation is on (a gated fix, no agreeing fix since); slip-aware: a wheel slips.
  bool slipping() const { return slipping_ || slippingWheels() != SLIP_NONE; }
  /// Slip-aware filter: the wheels loose or slipping beyond slip/speed_tolerance now (SlipWheel bits);
  /// SLIP_NONE otherwise.
  unsigned slippingWheels() const { return detector_ ? slippingAt(history_.back()) : SLIP_NONE; }
  /// Slip-aware filter: the state with the ground speed [m/s] and the wheels' slip speeds (kSpeed,
  /// kSlipRight, kSlipLeft), and its covariance; zero otherwise.
  const SlipVector& slipState() const { return history_.back().smean; }
  const SlipMatrix& slipCovariance() const { return history_.back().scov; }
  double groundSpeed() const { return slipState()(kSpeed); }
  /// The speed the loop is fed: while the slip-aware filter finds a wheel slipping, its ground speed; otherwise
  /// the encoders' speed as given (slip biases it, as it does the odometry). The traction control divides by it,
  /// so with the encoders' speed it sees no slip of both wheels at once: the reason the field profile turns the
  /// slip-aware filter on. Not the ground speed always: its acceleration is bounded (slip/max_acceleration), and a
  /// robot without the motors' limit accelerates faster on dry soil; fed the lagging speed, the inner loop pushed
  /// harder until the state diverged (fused_lockstep_slip.test, the thesis plant).
  double fedSpeed(double encoder_speed) const { return slippingWheels() != SLIP_NONE ? groundSpeed() : encoder_speed; }
  /// Slip-aware filter: what the detector found, and how long a wheel slipped.
  SlipCounts slipCounts() const { return detector_ ? detector_->counts() : SlipCounts{}; }
  const EkfParams& params() const { return params_; }

  // The pieces of one step, public for the tests (Jacobians against finite differences).
  /// Augmented vector a = (x, y, theta, b, d, u) -> next state.
  static Vector motion(const Eigen::Matrix<double, 6, 1>& a);
  /// d motion / d a.
  static Eigen::Matrix<double, 4, 6> motionJacobian(const Eigen::Matrix<double, 6, 1>& a);
  /// One whole prediction of (mean, covariance) over `in` lasting dt, with these parameters.
  static void propagate(const EkfParams& p, double dt, const EkfStepInput& in, Vector& mean, Matrix& cov);
  /// The fix update of (mean, covariance); returns the squared Mahalanobis distance of the innovation.
  /// `apply` false only computes it.
  static double update(const EkfFix& fix, Vector& mean, Matrix& cov, bool apply = true);
  /// Re-anchoring (file comment): x, y and their covariance from the fix, their cross terms zero.
  static void reanchor(const EkfFix& fix, Vector& mean, Matrix& cov);

 private:
  struct Entry {
    double t;
    Vector mean;
    Matrix cov;
    EkfStepInput input;  ///< the step that led here from the previous entry
    struct Applied {
      EkfFix fix;
      bool reanchor;
    };
    std::vector<Applied> fixes;  ///< applied here, in the order they came
    // The slip-aware filter only: its state (mean, cov above are its first four), the wheels left out
    // over the step that led here, and what was added to the variances of (v, sigma_R, sigma_L) before it.
    SlipVector smean = SlipVector::Zero();
    SlipMatrix scov = SlipMatrix::Zero();
    unsigned loose = SLIP_NONE;
    Eigen::Vector3d inflation = Eigen::Vector3d::Zero();
  };
  void pinBias(Vector& mean, Matrix& cov) const;
  /// e as the newest entry (the oldest dropped when history_length are kept).
  void append(const Entry& e);
  // The slip-aware filter's pieces.
  bool predictSlipAware(double t, const EkfStepInput& in);
  FixOutcome fuseSlipAware(const EkfFix& fix, std::size_t k);
  /// mean, cov := the first four of smean, scov (after pinning the bias).
  void settle(Entry& e) const;
  /// One step from `before` into e with e's stored input, verdict and inflation (no fixes).
  void stepSlipAware(const Entry& before, Entry& e) const;
  /// Entries after k propagated again from k with their stored inputs, verdicts and fixes.
  void repropagateSlipAware(std::size_t k);
  /// The entries after k take `wheels` as loose too.
  void markLoose(std::size_t k, unsigned wheels);
  /// The slips of `wheels` re-opened from entry k on: `open` [(m/s)²] added to their variance before the
  /// step after k.
  void reacquire(std::size_t k, unsigned wheels, double open);
  /// The wheels loose or slipping beyond slip/speed_tolerance at e.
  unsigned slippingAt(const Entry& e) const;

  EkfParams params_;
  // The last history_length entries, oldest first; a ring of that capacity allocated once (a new entry
  // takes the oldest one's place), not a block per step.
  boost::circular_buffer<Entry> history_;
  FixCounts counts_;
  int gated_in_a_row_ = 0;  // for fix/reanchor_after
  bool slipping_ = false;   // slip/inflation in force
  double half_track_;
  std::optional<SlipDetector> detector_;                         // slip/detect
  Eigen::Vector3d pending_inflation_ = Eigen::Vector3d::Zero();  // for the next step (re-acquired at the newest)
};

/// Holds fixes until the filter's time has passed stamp + delay, so that which fixes an estimate
/// includes depends on the stamps only, not on the order in which the fix and the odometry arrived.
class FixQueue {
 public:
  explicit FixQueue(double delay, std::size_t capacity = 64) : delay_(delay), capacity_(capacity), fixes_(capacity) {}
  /// Keeps the fix (the oldest goes when full: counted in dropped()).
  void push(const EkfFix& fix);
  /// The fixes with stamp + delay <= t (1 us tolerance), oldest stamp first, removed from the queue. The
  /// vector is the queue's own, valid until the next call (reused: no allocation per call).
  const std::vector<EkfFix>& due(double t);
  std::size_t size() const { return fixes_.size(); }
  long dropped() const { return dropped_; }

 private:
  double delay_;
  std::size_t capacity_;
  boost::circular_buffer<EkfFix> fixes_;  // allocated once at capacity_
  std::vector<EkfFix> due_;               // due()'s result
  long dropped_ = 0;
};

}  // namespace core
}  // namespace sowing_robot
