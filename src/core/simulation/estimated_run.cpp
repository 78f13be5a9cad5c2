#include "sowing_robot/core/simulation/estimated_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/planning/tool_engagement.h"
#include "sowing_robot/core/simulation/closed_loop.h"

namespace sowing_robot {
namespace core {

const char* feedbackName(Feedback f) {
  switch (f) {
    case Feedback::ground_truth: return "ground_truth";
    case Feedback::odometry: return "odometry";
    case Feedback::fused: return "fused";
  }
  return "?";
}

std::string parseFeedback(const std::string& name, Feedback& out) {
  for (Feedback f : {Feedback::ground_truth, Feedback::odometry, Feedback::fused})
    if (name == feedbackName(f)) {
      out = f;
      return "";
    }
  return "feedback '" + name + "' is none of ground_truth, odometry, fused";
}

std::string EstimatedRunConfig::validate() const {
  std::string e =
      firstError({sensors.validate(), estimator.validate(), traction ? traction->validate() : "", motor.validate(),
                  traction_control.validate(), speed_governor.validate(), hitch_control.validate()});
  if (!e.empty()) return e;
  if (speed_governor.enabled && !traction_control.enabled)
    return "speed_governor/enabled needs traction_control/enabled (the governor acts on its slip verdict)";
  if (hitch_control.enabled && !traction_control.enabled)
    return "hitch_control/enabled needs traction_control/enabled (the hitch acts on its grip verdict)";
  if (!allFinite(tool.x(), tool.y())) return "the tool point must be finite";
  for (std::size_t i = 0; i < patches.size(); ++i) {
    e = patches[i].validate("field/patches[" + std::to_string(i) + "]");
    if (!e.empty()) return e;
  }
  return "";
}

namespace {

Pose2D truePose(const State& s) { return {s[X], s[Y], s[THETA]}; }

/// plant_sim's sensors and state_estimator, as the closed loop's feedback source (closed_loop.h): the
/// encoders, the gyro and the fixes see every state; the controllers are fed the truth, the encoder
/// odometry or the EKF's estimate (config.feedback). Also keeps the fed pose's and the odometry's error
/// against the truth.
class SensorFeed {
 public:
  SensorFeed(const Scenario& sc, const EstimatedRunConfig& cfg)
      : cfg_(cfg),
        period_ns_(sc.control_period_ns),
        L_(sc.robot.L),
        dt_(secondsFromNanos(sc.control_period_ns)),
        encoders_(cfg.sensors, sc.robot.R, sc.robot.L),
        gyro_(cfg.sensors),
        fix_sensor_(cfg.sensors),
        // What the messages carry: the gyro's variance (sensor_msgs/Imu), the fix's (PoseWithCovarianceStamped).
        rate_variance_(cfg.sensors.imu.noise > 0.0 ? cfg.sensors.imu.noise * cfg.sensors.imu.noise : 0.0),
        fix_variance_(cfg.sensors.fix.sigma * cfg.sensors.fix.sigma),
        // state_estimator's increment_covariance_: the encoders' quantisation per step, nominal half track.
        increment_covariance_(encoderIncrementCovariance(cfg.estimator.increment_sigma, sc.robot.L)),
        queue_(cfg.estimator.fix_delay) {
    if (cfg.feedback == Feedback::fused) ekf_ = std::make_unique<Ekf>(cfg.estimator, L_);
  }

  /// plant_sim's sensors at the start state (PlantSensors' constructor): encoders and gyro reset, the first
  /// fix sampled at t = 0, the yaw rate measured once before the first period.
  void start(const State& s) {
    encoders_.reset(truePose(s), s[PHI_R], s[PHI_L]);
    gyro_.reset();
    fix_sensor_.reset(0.0);
    fix_sensor_.sample(0.0, truePose(s));
    yaw_rate_ = gyro_.measure(s[OMEGA]);
  }

  Fed observe(double t, const State& s, const Pose2D& truth, double, double) {
    // odom as published (the encoders' last update) and as a subscriber reads it back.
    const Odometry2D& odom = encoders_.last();
    const Pose2D odom_pose{odom.pose.x, odom.pose.y, yawThroughQuaternion(odom.pose.theta)};
    odometry_error_final_ = std::hypot(odom.pose.x - s[X], odom.pose.y - s[Y]);
    odometry_error_max_ = std::max(odometry_error_max_, odometry_error_final_);
    // The traction control's wheel speeds are the encoders' (windowed); its ground twist is the fed one.
    const double wheel_r = odom.v + L_ * odom.omega, wheel_l = odom.v - L_ * odom.omega;
    Fed fed{truth, s[V], s[OMEGA], {wheel_r, wheel_l, s[V], s[OMEGA]}};
    if (cfg_.feedback == Feedback::odometry) {
      fed = {odom_pose, odom.v, odom.omega, {wheel_r, wheel_l, odom.v, odom.omega}};
    } else if (ekf_) {
      fuse(t, odom_pose);
      const Ekf::Vector& m = ekf_->mean();
      const double omega = yaw_rate_ - m(Ekf::BIAS), v = ekf_->fedSpeed(odom.v);
      fed = {{m(Ekf::X), m(Ekf::Y), yawThroughQuaternion(m(Ekf::THETA))}, v, omega, {wheel_r, wheel_l, v, omega}};
    }
    const double error = std::hypot(fed.pose.x - s[X], fed.pose.y - s[Y]);
    fed_sq_ += error * error;
    ++fed_count_;
    fed_error_max_ = std::max(fed_error_max_, error);
    fed_heading_error_max_ = std::max(fed_heading_error_max_, std::fabs(wrapAngle(fed.pose.theta - s[THETA])));
    return fed;
  }

  /// SimulatedPlant::step: the sensors on the new state of period k, stamped on the grid.
  void afterStep(std::int64_t k, const State& s) {
    if (!std::isfinite(s.sum())) return;
    encoders_.update(s[PHI_R], s[PHI_L], dt_);
    yaw_rate_ = gyro_.measure(s[OMEGA]);
    fix_sensor_.sample(secondsFromNanos(k * period_ns_), truePose(s));
  }

  void finish(EstimatedRunResult& out) const {
    out.odometry_error_final = odometry_error_final_;
    out.odometry_error_max = odometry_error_max_;
    out.fed_heading_error_max = fed_heading_error_max_;
    if (out.run.diverged) {
      out.fed_error_rms = out.fed_error_max = std::numeric_limits<double>::infinity();
    } else {
      out.fed_error_max = fed_error_max_;
      out.fed_error_rms = fed_count_ > 0 ? std::sqrt(fed_sq_ / static_cast<double>(fed_count_)) : 0.0;
    }
    if (ekf_) out.fixes = ekf_->counts();
    out.fixes_lost_from_queue = queue_.dropped();
  }

 private:
  /// state_estimator's period: the fixes published at t (stamps on the nanosecond grid, as the header
  /// carries them) into its queue; the first period resets the EKF at the odometry's pose, later ones
  /// predict over the increment that turns the previous odometry pose into this one, with the yaw rate;
  /// then the queue's due fixes are fused.
  void fuse(double t, const Pose2D& odom_pose) {
    for (const FixMeasurement& m : fix_sensor_.due(t)) {
      EkfFix f;
      f.stamp = secondsFromNanos(static_cast<std::int64_t>(std::llround(m.stamp * 1e9)));
      f.xy = m.xy;
      f.covariance << fix_variance_, 0.0, 0.0, fix_variance_;
      queue_.push(f);
    }
    if (!ekf_->initialised()) {
      ekf_->reset(t, odom_pose);
    } else {
      EkfStepInput in;
      in.dtheta = wrapAngle(odom_pose.theta - last_odom_.theta);
      const double mid = last_odom_.theta + 0.5 * in.dtheta;
      in.distance = (odom_pose.x - last_odom_.x) * std::cos(mid) + (odom_pose.y - last_odom_.y) * std::sin(mid);
      in.covariance = increment_covariance_;
      in.has_rate = true;
      in.rate = yaw_rate_;
      in.rate_variance = rate_variance_;
      ekf_->predict(t, in);  // refused only for a non-finite input: the estimate then stays
    }
    for (const EkfFix& f : queue_.due(ekf_->time())) ekf_->fuse(f);
    last_odom_ = odom_pose;
  }

  const EstimatedRunConfig& cfg_;
  const std::int64_t period_ns_;
  const double L_;  // nominal half track [m]
  const double dt_;
  EncoderOdometry encoders_;
  YawRateSensor gyro_;
  PositionFixSensor fix_sensor_;
  const double rate_variance_, fix_variance_;
  const Eigen::Matrix2d increment_covariance_;
  std::unique_ptr<Ekf> ekf_;
  FixQueue queue_;
  Pose2D last_odom_;  // state_estimator's last_odom_, as poseOf reads it
  double yaw_rate_ = 0.0;
  double fed_sq_ = 0.0, fed_error_max_ = 0.0, fed_heading_error_max_ = 0.0;
  std::int64_t fed_count_ = 0;
  double odometry_error_final_ = 0.0, odometry_error_max_ = 0.0;
};

/// What the simulation knows beyond the measurements at a no-traction verdict: the grip budget of the soil
/// under the robot there (no slip: nothing to say).
template <typename PlantT>
std::string gripDiagnosis(const Scenario& sc, const EstimatedRunConfig& cfg, const PlantT& plant, const Pose2D& where) {
  if constexpr (!PlantT::kTraction) {
    return "";
  } else {
    return core::gripDiagnosis(sc.robot, sc.disturbance.mass_scale, *cfg.traction, plant.plant.soil(),
                               {where.x, where.y});
  }
}

template <typename PlantT>
EstimatedRunResult run(const Scenario& sc, const EstimatedRunConfig& cfg, PlantT& plant, ReferenceSource& reference,
                       bool keep_samples, const std::function<void(const EstimatedSample&)>& trace) {
  plant.plant.setMotor(cfg.motor);
  std::unique_ptr<OuterController> outer = makeOuterController(sc);
  std::unique_ptr<InnerController> inner = makeInnerController(sc);
  SensorFeed feed(sc, cfg);
  ToolRule tool{PlantT::kTraction && cfg.traction && cfg.traction->draft_force > 0.0, cfg.tool,
                ToolEngagement(cfg.seeding, cfg.tool_rows, cfg.tool_rows_open_ended)};
  LoopLayers layers;
  layers.tool = &tool;
  if (cfg.traction) layers.high_slip = 2.0 * cfg.traction->slip_peak;
  std::optional<CommandLimiter> limiter;
  if (cfg.limits.enabled) {
    limiter.emplace(cfg.limits);
    layers.limiter = &*limiter;
  }
  std::optional<TractionControl> traction_control;
  std::optional<TractionMonitor> monitor;
  if (cfg.traction_control.enabled) {
    traction_control.emplace(cfg.traction_control, sc.robot.L);
    layers.traction_control = &*traction_control;
    monitor.emplace(cfg.traction_control);
    layers.monitor = &*monitor;
  }
  std::optional<HitchControl> hitch;
  if (cfg.hitch_control.enabled) {
    hitch.emplace(cfg.hitch_control);
    layers.hitch = &*hitch;
  }
  std::optional<GovernedReference> governed;
  if (cfg.speed_governor.enabled) {
    governed.emplace(reference, cfg.speed_governor);
    layers.governor = &*governed;
    layers.governed_time_back = cfg.governed_time_back;
  }
  EstimatedRunResult out = closedLoop(sc, plant, feed, *outer, *inner, governed ? *governed : reference, keep_samples,
                                      trace, RunStop{}, layers);
  if (hitch) out.hitch_raises = hitch->raises();
  if (out.no_traction.detected) out.no_traction.diagnosis = gripDiagnosis(sc, cfg, plant, out.no_traction.where);
  return out;
}

}  // namespace

EstimatedRunResult runEstimatedLoop(const Scenario& sc, const EstimatedRunConfig& cfg, ReferenceSource& reference,
                                    bool keep_samples, const std::function<void(const EstimatedSample&)>& trace) {
  std::string e = firstError({sc.validate(), cfg.validate()});
  if (e.empty() && cfg.traction) {  // the motors against the heaviest going: the worst soil's rolling resistance
    double rolling = cfg.traction->rolling_resistance;
    for (const SoilPatch& p : cfg.patches) rolling = std::max(rolling, p.rolling_resistance);
    e = checkMotorsCanMove(cfg.motor, sc.robot, sc.disturbance.mass_scale, rolling, cfg.traction->draft_force);
  }
  if (!e.empty()) throw std::invalid_argument(e);
  if (!cfg.traction) {
    NoSlipPlant plant{Plant(sc.robot, sc.disturbance), sc.robot.L};
    return run(sc, cfg, plant, reference, keep_samples, trace);
  }
  SlipPlant plant{TractionPlant(sc.robot, sc.disturbance, *cfg.traction), sc.robot.R};
  plant.plant.setSoil(SoilMap(cfg.patches));
  plant.plant.setToolPoint(cfg.tool);
  return run(sc, cfg, plant, reference, keep_samples, trace);
}

}  // namespace core
}  // namespace sowing_robot
