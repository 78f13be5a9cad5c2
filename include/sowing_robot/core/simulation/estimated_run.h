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

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sowing_robot/core/control/command_limits.h"
#include "sowing_robot/core/control/hitch_control.h"
#include "sowing_robot/core/control/traction_control.h"
#include "sowing_robot/core/control/traction_monitor.h"
#include "sowing_robot/core/estimation/ekf.h"
#include "sowing_robot/core/model/motor.h"
#include "sowing_robot/core/model/sensors.h"
#include "sowing_robot/core/model/soil_map.h"
#include "sowing_robot/core/model/traction.h"
#include "sowing_robot/core/planning/seeding.h"
#include "sowing_robot/core/planning/speed_governor.h"
#include "sowing_robot/core/simulation/runner.h"

namespace sowing_robot {
namespace core {

/// What the controllers close the loop on (sim.launch feedback:=).
enum class Feedback { ground_truth, odometry, fused };
/// "ground_truth", "odometry", "fused".
const char* feedbackName(Feedback f);
/// Parses a name; "" on success, else one line naming the allowed ones.
std::string parseFeedback(const std::string& name, Feedback& out);

/// Everything the estimated loop adds to a Scenario.
struct EstimatedRunConfig {
  Feedback feedback = Feedback::ground_truth;
  /// Set: the traction plant with these parameters (its `enabled` is not looked at); unset: the no-slip Plant.
  std::optional<TractionParams> traction;
  std::vector<SoilPatch> patches;    ///< traction only
  Eigen::Vector2d tool{-0.45, 0.0};  ///< the tool point in base_link (the URDF's tool_link) [m]
  /// The rows the plant's tool rule (tool_engagement.h) lowers the tool on while traction->draft_force > 0.
  std::vector<RowSegment> tool_rows;
  bool tool_rows_open_ended = false;
  SeedingParams seeding;  ///< the tool rule's parameters (detour_margin as config/seed_drill.yaml: 4 m)
  SensorParams sensors;   ///< sensors.yaml defaults
  EkfParams estimator;    ///< estimator.yaml defaults (feedback fused)
  MotorParams motor;      ///< the drive motors (off: the commanded torque reaches the wheel)
  /// Bounds on the outer loop's command, kinematic_controller's limits/ (off: the command as computed).
  CommandLimitsParams limits;
  /// Between the inner loop and the motors: each wheel's torque capped while it slips (off: unchanged).
  TractionControlParams traction_control;
  /// The target slowed along its path while a wheel slips (needs traction_control; off: planned timing).
  SpeedGovernorParams speed_governor;
  /// The tool raised while the traction control holds the wheels at their grip limit (needs
  /// traction_control; off: the seed drill's rule alone).
  HitchControlParams hitch_control;
  /// With the speed governor: the run gets back the time the governor took from the path, i.e. it lasts
  /// until the governed path time has run the scenario's duration (at most twice the duration), so that a
  /// robot slowed for grip is judged at the same point of its path as one that was not. The benchmark's
  /// field runs set it (their finish check reads the path's time); false: the scenario's duration.
  bool governed_time_back = false;

  /// "" or the first bad parameter as one line naming its key.
  std::string validate() const;
};

struct LoopLayers;  // closed_loop.h

/// One period as the estimated loop sees it: the LoopSample on the truth (errors against the truth), and
/// what the controllers were fed.
struct EstimatedSample {
  const LoopSample* loop;
  Pose2D fed;               ///< the pose the controllers got (truth, odometry or estimate), yaw through the quaternion
  double fed_v, fed_omega;  ///< the twist they got
  double slip_right = 0.0, slip_left = 0.0;  ///< traction: the wheels' slip ratios at this state
  bool tool_down = false;                    ///< traction with a draft: the tool is down over the next step
  WheelTorques sent;                         ///< the torques sent to the motors (after the layers) [N·m]
  /// The loop's layers this period (their state after it: ceilings, slip estimates, the governor's rate).
  const LoopLayers* layers = nullptr;
};

struct EstimatedRunResult {
  RunResult run;              ///< metrics on the truth
  double max_abs_slip = 0.0;  ///< traction: largest |slip ratio| of either wheel after a step
  /// Traction: time either wheel's |slip ratio| was above twice the friction peak's (traction/slip_peak) [s].
  double high_slip_time = 0.0;
  double tool_down_time = 0.0;  ///< traction with a draft: time the tool was down [s]
  /// Position error of the fed pose against the truth over the periods run [m] (0 for ground_truth).
  double fed_error_rms = 0.0, fed_error_max = 0.0;
  /// Heading error of the fed pose [rad], largest |.| over the run.
  double fed_heading_error_max = 0.0;
  /// Position error of the encoder odometry alone [m] at the end and its largest (any feedback).
  double odometry_error_final = 0.0, odometry_error_max = 0.0;
  FixCounts fixes;  ///< fused: what happened to the fixes
  long fixes_lost_from_queue = 0;
  double traction_control_time = 0.0;  ///< time a wheel slipped beyond the traction control's target [s]
  double governor_min_rate = 1.0;      ///< the slowest rate the speed governor gave the target
  /// Hitch control: the tool point's travel while the seed drill's rule had the tool down but the hitch
  /// held it up, i.e. the length of row left unsown [m]; and how often it raised the tool.
  double unsown_distance = 0.0;
  int hitch_raises = 0;
  /// With the traction control: the robot found without traction (the run then ended
  /// traction_control/no_traction_hold after the verdict, the robot held at rest).
  NoTractionReport no_traction;
};

/// Runs the scenario (plant, timing, start, disturbance incl. its phase, the outer/inner pair of
/// scenario.outer/inner with their gains) with `config`'s plant, sensors and feedback on `reference`.
/// trace (optional) sees every period. Throws std::invalid_argument when a parameter set does not validate.
EstimatedRunResult runEstimatedLoop(const Scenario& scenario, const EstimatedRunConfig& config,
                                    ReferenceSource& reference, bool keep_samples = true,
                                    const std::function<void(const EstimatedSample&)>& trace = {});

}  // namespace core
}  // namespace sowing_robot
