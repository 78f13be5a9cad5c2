// The slip-aware filter's algebra (ekf.h with estimator/slip/detect): the EKF's state (x, y, theta, b)
// plus the ground speed v of the axle midpoint and each drive wheel's slip speed, the speed of its rim
// beyond the ground speed of its contact point: s = (x, y, theta, b, v, sigma_R, sigma_L).
//
// One plant step of length dt, over the augmented vector a = (s, d_w, n_u, n_d):
//   d_w        the body's heading change as the wheels' difference gives it (a wide prior: the
//              measurements below fix it);
//   n_u, n_d   the body's white deviation from that rolling (distance_noise² and heading_noise² per metre
//              rolled at the estimated speed: the odometry's slip model, Siegwart's, as the plain filter);
//   the body moves u = v dt + n_u, d = d_w + n_d (midpoint heading, as the encoder odometry);
//   v' = v + w_v, sigma_i' = sigma_i + w_i: random walks (slip/speed_walk, slip/slip_walk).
// Measurements, one exact Kalman update of them all:
//   each wheel's travel, unless it is loose (slip_detector.h),
//       s_R = (v + sigma_R) dt + L d_w + e_R,   s_L = (v + sigma_L) dt - L d_w + e_L,
//     e the encoders' quantisation (the caller's covariance of (distance, dtheta) mapped onto the wheels);
//   the yaw rate, r dt = d_w + n_d + b dt + n (as the plain filter).
// So the wheels' difference against the gyro measures sigma_R - sigma_L; their sum measures v + the
// common slip, which the fixes (through the position) split: the encoders keep their precision step to
// step while the fixes calibrate their slip. A loose wheel's travel is left out: the other wheel, or the
// speed's random walk and the fixes, carry the distance; the gyro the heading. After the step |v| is held
// within max_ground_speed (a clamp of the mean), so no encoder and no model moves the estimate faster.
#pragma once

#include <Eigen/Core>

#include "sowing_robot/core/estimation/slip_detector.h"

namespace sowing_robot {
namespace core {

struct EkfParams;
struct EkfStepInput;
struct EkfFix;

using SlipVector = Eigen::Matrix<double, 7, 1>;
using SlipMatrix = Eigen::Matrix<double, 7, 7>;
/// Indices of the ground speed and the wheels' slip speeds in SlipVector (0-3 as Ekf::Index).
enum SlipIndex { kSpeed = 4, kSlipRight = 5, kSlipLeft = 6 };

/// Augmented vector a = (x, y, theta, b, v, sigma_R, sigma_L, d_w, n_u, n_d) -> next state.
SlipVector slipAwareMotion(const Eigen::Matrix<double, 10, 1>& a, double dt);
/// d slipAwareMotion / d a.
Eigen::Matrix<double, 7, 10> slipAwareJacobian(const Eigen::Matrix<double, 10, 1>& a, double dt);

/// One whole step (the file comment) with the `loose` wheels (SlipWheel bits) left out. half_track: the
/// nominal L.
void slipAwarePropagate(const EkfParams& p, double half_track, double dt, const EkfStepInput& in, unsigned loose,
                        SlipVector& mean, SlipMatrix& cov);
/// The fix update; returns the innovation's squared Mahalanobis distance, and `along` its along-track part
/// over its std (positive: the fix ahead of the estimate in the direction of v). apply false: only computes.
/// keep_heading (both wheels slipping): the fix corrects position, speed and slips but neither heading nor
/// bias (their gain rows zero: a Schmidt "consider" update). Why: with no wheel measuring the ground
/// speed, a robot that hardly moves tells the fixes nothing about its heading, but the linearised filter,
/// moving at its noisy speed estimate, takes their scatter for heading information: in a 60 s stall the
/// bias's std shrank by half while its error grew, and the heading error reached 3 std.
double slipAwareUpdate(const EkfFix& fix, SlipVector& mean, SlipMatrix& cov, bool apply, double* along = nullptr,
                       bool keep_heading = false);
/// Re-anchoring: x, y and their covariance from the fix, their cross terms zero.
void slipAwareReanchor(const EkfFix& fix, SlipVector& mean, SlipMatrix& cov);

}  // namespace core
}  // namespace sowing_robot
