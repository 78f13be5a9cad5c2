// The closed loop's feedback sources (closed_loop.h's Feed): what the controllers are fed each period.
//   StateFeed:  the plant's own state (perfect sensing, no sensors run).
//   SensorFeed: the plant's sensors (SensorSuite) and state_estimator's filter: the controllers are fed the
//               truth, the encoder odometry or the EKF's estimate (LoopConfig::feedback).
// SensorSuite is the set of sensors the plant carries (model/sensors.h), read on the true state: the same
// class plant_sim publishes from (ros/plant_sim/sensors.h), so the in-process loop and the node pipeline
// read them in one way. A new sensor: its class and its entry in model/sensors.h's PlantSensorSet (the suite
// builds, starts and reads every entry), and its message in plant_sim (the ROS side's one registration).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <tuple>
#include <type_traits>
#include <vector>

#include "sowing_robot/core/estimation/ekf.h"
#include "sowing_robot/core/model/sensors.h"
#include "sowing_robot/core/simulation/loop_types.h"

namespace sowing_robot {
namespace core {

/// What the controllers are fed in one period.
struct Fed {
  Pose2D pose;  ///< yaw through the quaternion round trip
  double v, omega;
  WheelGroundSpeeds speeds;  ///< what the traction control measures: the wheels' R W, the ground twist
};

/// Feedback: the plant's own state (perfect sensing: the wheels' true speeds too; no sensors run).
struct StateFeed {
  void start(const State&) {}
  Fed observe(double, const State& s, const Pose2D& truth, double wheel_right, double wheel_left) {
    return {truth, s[V], s[OMEGA], {wheel_right, wheel_left, s[V], s[OMEGA]}};
  }
  void afterStep(std::int64_t, const State&) {}
  void finish(LoopResult&) const {}
};

/// The sensors the plant carries (model/sensors.h's PlantSensorSet), read on its true state: the wheel encoders'
/// dead reckoning (nominal R, L), the yaw-rate gyro and the position fix (sampled, delivered after its latency).
class SensorSuite {
 public:
  SensorSuite(const SensorParams& params, const RobotParams& nominal)
      : sensors_(build(params, nominal, static_cast<PlantSensorSet*>(nullptr))) {}

  /// At the start state, time 0: every sensor's start() (the encoders and the gyro reset, the first fix sampled,
  /// the yaw rate measured once before the first period).
  void start(const State& s) {
    std::apply([&s](auto&... sensor) { (sensor.start(s), ...); }, sensors_);
  }
  /// Every sensor on the true state s at time t, dt after the previous reading.
  void update(double t, const State& s, double dt) {
    std::apply([&](auto&... sensor) { (sensor.read(t, s, dt), ...); }, sensors_);
  }
  /// One sensor of the set, by its class.
  template <class Sensor>
  Sensor& sensor() {
    return std::get<Sensor>(sensors_);
  }
  template <class Sensor>
  const Sensor& sensor() const {
    return std::get<Sensor>(sensors_);
  }

  /// The encoders' last dead-reckoning update.
  const Odometry2D& odometry() const { return encoders().last(); }
  const EncoderOdometry& encoders() const { return sensor<EncoderOdometry>(); }
  /// The gyro's last reading [rad/s].
  double yawRate() const { return sensor<YawRateSensor>().last(); }
  /// The fixes whose latency has passed by t (each once).
  const std::vector<FixMeasurement>& dueFixes(double t) { return sensor<PositionFixSensor>().due(t); }

 private:
  /// A sensor built from the parameters and the nominal robot when it takes both, else from the parameters.
  template <class Sensor>
  static Sensor make(const SensorParams& params, const RobotParams& nominal) {
    if constexpr (std::is_constructible_v<Sensor, const SensorParams&, const RobotParams&>)
      return Sensor(params, nominal);
    else
      return Sensor(params);
  }
  template <class... Sensors>
  static std::tuple<Sensors...> build(const SensorParams& params, const RobotParams& nominal, std::tuple<Sensors...>*) {
    return std::tuple<Sensors...>(make<Sensors>(params, nominal)...);
  }

  PlantSensorSet sensors_;
};

/// plant_sim's sensors and state_estimator, as the closed loop's feedback source (closed_loop.h): the
/// encoders, the gyro and the fixes see every state; the controllers are fed the truth, the encoder
/// odometry or the EKF's estimate (config.feedback). Also keeps the fed pose's and the odometry's error
/// against the truth.
class SensorFeed {
 public:
  SensorFeed(const Scenario& sc, const LoopConfig& cfg)
      : cfg_(cfg),
        period_ns_(sc.control_period_ns),
        L_(sc.robot.L),
        dt_(secondsFromNanos(sc.control_period_ns)),
        sensors_(cfg.sensors, sc.robot),
        // What the messages carry: the gyro's variance (sensor_msgs/Imu), the fix's (PoseWithCovarianceStamped).
        rate_variance_(cfg.sensors.imu.noise > 0.0 ? cfg.sensors.imu.noise * cfg.sensors.imu.noise : 0.0),
        fix_variance_(cfg.sensors.fix.sigma * cfg.sensors.fix.sigma),
        // state_estimator's increment_covariance_: the encoders' quantisation per step, nominal half track.
        increment_covariance_(encoderIncrementCovariance(cfg.estimator.increment_sigma, sc.robot.L)),
        queue_(cfg.estimator.fix_delay) {
    if (cfg.feedback == Feedback::fused) ekf_ = std::make_unique<Ekf>(cfg.estimator, L_);
  }

  /// plant_sim's sensors at the start state (SensorSuite::start).
  void start(const State& s) { sensors_.start(s); }

  Fed observe(double t, const State& s, const Pose2D& truth, double, double) {
    // odom as published (the encoders' last update) and as a subscriber reads it back.
    const Odometry2D& odom = sensors_.odometry();
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
      const double omega = sensors_.yawRate() - m(Ekf::BIAS), v = ekf_->fedSpeed(odom.v);
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
    sensors_.update(secondsFromNanos(k * period_ns_), s, dt_);
  }

  void finish(LoopResult& out) const {
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
    for (const FixMeasurement& m : sensors_.dueFixes(t)) {
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
      in.rate = sensors_.yawRate();
      in.rate_variance = rate_variance_;
      ekf_->predict(t, in);  // refused only for a non-finite input: the estimate then stays
    }
    for (const EkfFix& f : queue_.due(ekf_->time())) ekf_->fuse(f);
    last_odom_ = odom_pose;
  }

  const LoopConfig& cfg_;
  const std::int64_t period_ns_;
  const double L_;  // nominal half track [m]
  const double dt_;
  SensorSuite sensors_;
  const double rate_variance_, fix_variance_;
  const Eigen::Matrix2d increment_covariance_;
  std::unique_ptr<Ekf> ekf_;
  FixQueue queue_;
  Pose2D last_odom_;  // state_estimator's last_odom_, as poseOf reads it
  double fed_sq_ = 0.0, fed_error_max_ = 0.0, fed_heading_error_max_ = 0.0;
  std::int64_t fed_count_ = 0;
  double odometry_error_final_ = 0.0, odometry_error_max_ = 0.0;
};

}  // namespace core
}  // namespace sowing_robot
