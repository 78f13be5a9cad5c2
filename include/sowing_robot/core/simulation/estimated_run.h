// The in-process closed loop with an estimate in the loop (issue 16's missing piece): the plant (the
// no-slip Plant, or the TractionPlant with soil patches and the tool's draft), the seeded sensors
// (sensors.h), and a feedback mode: the controllers are fed the truth, the encoder odometry, or the EKF's
// estimate (ekf.h), while the metrics are taken on the TRUTH (as run_monitor scores ground_truth in the
// node pipeline).
//
// The order of operations mirrors the node pipeline in lockstep (sim.launch feedback:=..., traction:=...),
// so that the two give the same numbers:
//   period k, t_k = k * period (stamp grid, secondsFromNanos as ros::Time::toSec):
//     plant_sim publishes ground_truth (the state), odom (the encoders' last update), imu (the yaw rate
//       measured at the last update) and the fixes delivered by t_k (PositionFixSensor::due);
//     state_estimator (fused): pushes the fixes into its FixQueue (estimator/fix/delay), then at the first
//       period resets the EKF at the odometry's pose, later predicts over the increments that turn the
//       previous odometry pose into this one (the poses through the quaternion round trip, as poseOf reads
//       them) with the yaw rate and encoderIncrementCovariance(), then fuses the queue's due fixes;
//     the outer and inner controllers get the fed pose (through the quaternion) and its twist: truth (v,
//       omega of the state), odometry (the encoders' windowed v, omega), fused (the encoders' v and the
//       gyro's rate less the estimated bias);
//     the tool rule (traction with a draft) sees the true tool point; the plant steps; the sensors
//       update on the new state at t_{k+1} (encoders, yaw rate, fix sampling), as SimulatedPlant::step.
// With feedback ground_truth the sensors still run (their output unused), so a run's numbers do not
// depend on it; the controllers then see exactly what runClosedLoop's see (test_estimated_run: equal bit
// for bit to runClosedLoop). Both are the one loop of closed_loop.h, with another feedback source.
#pragma once

#include <functional>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/simulation/loop_types.h"

namespace sowing_robot {
namespace core {

/// Runs the scenario (plant, timing, start, disturbance incl. its phase, the outer/inner pair of
/// scenario.outer/inner with their gains) with `config`'s plant, sensors and feedback on `reference`.
/// trace (optional) sees every period. Throws std::invalid_argument when a parameter set does not validate.
EstimatedRunResult runEstimatedLoop(const Scenario& scenario, const EstimatedRunConfig& config,
                                    ReferenceSource& reference, bool keep_samples = true,
                                    const std::function<void(const EstimatedSample&)>& trace = {});

}  // namespace core
}  // namespace sowing_robot
