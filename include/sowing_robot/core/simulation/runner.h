// The in-process closed loop's entry point, runClosedLoop: plant + outer controller (Kanayama by default) +
// inner controller (the sliding-mode controller by default) + reference, stepped exactly as the node
// pipeline steps them in lockstep (same order, same times, same yaw round trip), so the two give the same
// numbers. Used by the benchmark, the tuner, the field runs, the metrics tool and the Python module. The
// pair is chosen by Scenario::outer / inner (controller_factory.h); the loop's types are loop_types.h's.
//
// With a LoopConfig, the run is given its plant (no-slip or traction), its sensors and its feedback source
// (LoopConfig::feedback: the truth, the encoders' odometry or the EKF); without one, the no-slip plant is fed
// its own true state and no sensor runs (the thesis loop, and the fastest: the controllers as concrete types).
// With a LoopConfig the plant is the no-slip Plant or the TractionPlant with soil patches and the tool's
// draft, the seeded sensors (model/sensors.h) run, and the controllers are fed the truth, the encoder
// odometry, or the EKF's estimate (ekf.h), while the metrics are taken on the TRUTH (as run_monitor scores
// ground_truth in the node pipeline).
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
// depend on it; the controllers then see exactly what the truth-fed overloads' see (test_estimated_run:
// equal bit for bit). All are the one loop of closed_loop.h, with another feedback source.
#pragma once

#include <functional>

#include "sowing_robot/core/common/reference.h"
#include "sowing_robot/core/simulation/loop_types.h"

namespace sowing_robot {
namespace core {

/// Run the scenario with the given reference. trace (optional) sees every period; keep_samples turns
/// on the time-domain figures (rise/settling/overshoot).
RunResult runClosedLoop(const Scenario& scenario, ReferenceSource& reference, bool keep_samples = true,
                        const std::function<void(const LoopSample&)>& trace = {}, const RunStop& stop = {});

/// The same run with a RunTally fed every period (inlined into the loop; the same numbers as a trace
/// callback calling tally.add()).
RunResult runClosedLoop(const Scenario& scenario, ReferenceSource& reference, bool keep_samples, RunTally& tally);

/// The same loop with caller-built controllers behind the run-time interfaces (virtual calls; the
/// Scenario's outer/inner choice and gains are then ignored, its plant, timing and start are used).
RunResult runClosedLoop(const Scenario& scenario, ReferenceSource& reference, OuterController& outer,
                        InnerController& inner, bool keep_samples = true,
                        const std::function<void(const LoopSample&)>& trace = {}, const RunStop& stop = {});

/// Runs the scenario (plant, timing, start, disturbance incl. its phase, the outer/inner pair of
/// scenario.outer/inner with their gains) with `config`'s plant, sensors and feedback on `reference`.
/// trace (optional) sees every period. Throws std::invalid_argument when a parameter set does not validate.
LoopResult runClosedLoop(const Scenario& scenario, const LoopConfig& config, ReferenceSource& reference,
                         bool keep_samples = true, const std::function<void(const EstimatedSample&)>& trace = {});

}  // namespace core
}  // namespace sowing_robot
