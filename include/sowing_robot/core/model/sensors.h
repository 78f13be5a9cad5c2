// What the robot can measure of itself, ROS-free and seeded: wheel encoders turned
// into dead-reckoning odometry, a yaw-rate gyro, and a position fix with latency and dropouts. The plant
// wrapper (ros/plant_sim/sensors.h) feeds them the true state; the estimator (core/estimation/ekf.h) reads their
// output.
//
// Encoders. Each wheel's reading is a tick count floor(phi / res + n) with res = 2π / ticks_per_turn and
// n ~ N(0, noise²) drawn per reading (tick jitter: the count does not wander, so without slip the wheel
// angles stay within one tick of the truth). Dead reckoning integrates the increments of the counts with
// the NOMINAL R and L (what the controllers believe), heading at the increment's midpoint:
//   Δs_i = R Δφ_i,  Δs = (Δs_R + Δs_L) / 2,  Δθ = (Δs_R − Δs_L) / (2L),
//   x += Δs cos(θ + Δθ/2),  y += Δs sin(θ + Δθ/2),  θ += Δθ.
// With no slip the plant's wheel angles are exactly ∫(v ± Lω)/R, so the only error is the quantisation:
// |θ error| < R res / L, and the position error is below R res + (distance travelled) · R res / L
// (test/core/model/test_sensors.cpp). Under slip the wheels turn more than the body moves, and odometry drifts.
// Covariance: the pose covariance P grows as P ← F P Fᵀ + G Q Gᵀ (F, G the Jacobians of the update in
// the pose and in (Δs_R, Δs_L)), Q = diag(k |Δs_R|, k |Δs_L|) with k = travel_variance (the unmodelled
// slip and radius error, per metre: Siegwart's odometry model). The quantisation and jitter errors are
// NOT added per update: those of consecutive increments telescope (each reading's error enters one
// increment with + and the next with −), so adding their variance at 1 kHz would overstate the drift by
// orders of magnitude; incrementVariance() gives it for a filter that wants it per increment.
// Velocities are the count increments over the last velocity_window seconds (a 1 kHz difference of
// single ticks would be mostly quantisation: at 1 m/s a 1 ms step is 3-4 ticks of 2048 per turn).
//
// Yaw rate: omega + bias + N(0, noise²), one draw per measure().
//
// Position fix: the true axle midpoint + N(0, sigma²) on x and y, sampled at the first sample() call at
// or after t0 + n / rate (t0: reset), stamped with that call's time (the measurement time); delivered by
// due(t) once t >= stamp + latency. A sample whose stamp lies in [dropout_start, dropout_start +
// dropout_duration) is lost (its noise is still drawn, so the other samples do not depend on the window).
//
// Every sensor has its own std::mt19937_64, seeded from SensorParams::seed and a per-sensor offset
// (kEncoderSeedOffset, ...), so adding one sensor's draws never changes another's.
//
// The plant carries the sensors of PlantSensorSet (the end of this file): SensorSuite (simulation/sensor_feeds.h)
// builds each from (SensorParams, the nominal RobotParams) or from SensorParams alone, and reads each on the true
// state through start(state) at time 0 and read(t, state, dt) every step. A new sensor: its class here with those
// two, its parameters in SensorParams and sensorsTable(), and its entry in PlantSensorSet; its message is one
// registration in ros/plant_sim/sensors.cpp.
#pragma once

#include <Eigen/Core>
#include <boost/circular_buffer.hpp>
#include <cstdint>
#include <deque>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/model/robot_params.h"

namespace sowing_robot {
namespace core {

struct EncoderParams {
  int ticks_per_turn;      ///< counts per wheel revolution
  double noise;            ///< std of the per-reading tick jitter [ticks]; 0 = pure quantisation
  double travel_variance;  ///< growth of each wheel's travel variance per metre travelled [m²/m] (covariance only)
  double velocity_window;  ///< [s] velocities are the count increments over this long
};
struct ImuParams {
  double noise;  ///< std of the yaw-rate noise [rad/s]
  double bias;   ///< constant yaw-rate bias [rad/s]
};
struct FixParams {
  double rate;              ///< [Hz]
  double sigma;             ///< std of x and y [m]
  double latency;           ///< [s] from measurement to delivery
  double dropout_start;     ///< [s] sim time the dropout begins
  double dropout_duration;  ///< [s] 0 = no dropout
};

/// All sensors' parameters. Defaults, ranges, units and meanings: sensorsTable().
struct SensorParams {
  SensorParams();
  std::uint64_t seed;  ///< base seed of every sensor's generator
  EncoderParams encoder;
  ImuParams imu;
  FixParams fix;

  /// checkRanges() (every key named as in the table: "sensors/fix/rate = ...").
  std::string validate() const;
};
/// sensors/{seed, encoder/{ticks_per_turn, noise, travel_variance, velocity_window}, imu/{noise, bias},
/// fix/{rate, sigma, latency, dropout_start, dropout_duration}}.
const ParamTable<SensorParams>& sensorsTable();

/// Seed offsets of the sensors' generators.
constexpr std::uint64_t kEncoderSeedOffset = 1, kImuSeedOffset = 2, kFixSeedOffset = 3;

/// A generator seeded from (seed, offset) through std::seed_seq (neighbouring seeds give unrelated streams).
std::mt19937_64 sensorGenerator(std::uint64_t seed, std::uint64_t offset);

/// Dead-reckoning output of one update.
struct Odometry2D {
  Pose2D pose;
  double v = 0.0, omega = 0.0;                           ///< [m/s], [rad/s] over the velocity window
  double delta_s = 0.0, delta_theta = 0.0;               ///< [m], [rad] this update's increments
  double delta_right = 0.0, delta_left = 0.0;            ///< [m] this update's wheel travels R Δφ_i
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< of (x, y, theta)
};

class EncoderOdometry {
 public:
  /// R, L: the NOMINAL wheel radius and half track [m]. Throws std::invalid_argument for invalid params
  /// or R, L not finite and > 0.
  EncoderOdometry(const SensorParams& params, double R, double L);
  /// The dead reckoning of the nominal robot (its R and L).
  EncoderOdometry(const SensorParams& params, const RobotParams& nominal)
      : EncoderOdometry(params, nominal.R, nominal.L) {}

  /// Start at `pose` with zero covariance; the wheels' true angles are phi_r, phi_l (read once, so the
  /// first increment counts from here). The generator is re-seeded.
  void reset(const Pose2D& pose, double phi_r, double phi_l);
  /// Read both encoders at the true wheel angles [rad], dt [s] after the previous reading, and integrate.
  /// Throws std::invalid_argument for non-finite angles or dt <= 0.
  Odometry2D update(double phi_r, double phi_l, double dt);

  /// Tick count of a reading of the true angle phi (advances the generator when noise > 0).
  std::int64_t read(double phi);
  double resolution() const { return resolution_; }  ///< [rad] per tick
  /// Variance [m²] of one wheel-travel increment from quantisation and jitter: (R res)² (1/6 + 2 noise²).
  double incrementVariance() const { return q0_; }
  const Odometry2D& last() const { return out_; }

  /// SensorSuite's reading: reset at the state's pose and wheel angles; update on its wheel angles.
  void start(const State& s) { reset({s[X], s[Y], s[THETA]}, s[PHI_R], s[PHI_L]); }
  void read(double, const State& s, double dt) { update(s[PHI_R], s[PHI_L], dt); }

 private:
  SensorParams params_;
  double R_, L_, resolution_, q0_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::int64_t count_r_ = 0, count_l_ = 0;
  struct Past {
    std::int64_t r, l;
    double dt;
  };
  // The counts of the readings within velocity_window, oldest first: a ring, grown when full (a step
  // allocates nothing once it holds a window's readings).
  boost::circular_buffer<Past> window_;
  double window_time_ = 0.0;  // sum of window_'s dt after its first entry
  Odometry2D out_;
};

class YawRateSensor {
 public:
  /// Throws std::invalid_argument for invalid params.
  explicit YawRateSensor(const SensorParams& params);
  void reset();  ///< re-seed
  /// omega_true + bias + noise [rad/s].
  double measure(double omega_true);
  double noise() const { return params_.imu.noise; }

  /// SensorSuite's reading: re-seeded and measured once at the start state (before the first period), then
  /// once per step; last() is the latest measurement [rad/s].
  void start(const State& s) {
    reset();
    last_ = measure(s[OMEGA]);
  }
  void read(double, const State& s, double) { last_ = measure(s[OMEGA]); }
  double last() const { return last_; }

 private:
  SensorParams params_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  double last_ = 0.0;
};

struct FixMeasurement {
  double stamp = 0.0;  ///< [s] measurement time
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  double sigma = 0.0;  ///< [m] std of x and of y
};

/// When the position fix is measured: at t0 and every 1/rate after, each slot taken at the first call at or
/// after its time; none delivered inside the dropout. PositionFixSensor keeps one; state_estimator keeps its
/// own copy in lockstep, to know which fixes are on their way (it waits for them, so a run does not depend
/// on which connection delivers first).
class FixSchedule {
 public:
  explicit FixSchedule(const FixParams& params) : params_(params) {}
  /// First slot at t0.
  void reset(double t0);
  /// Call every step, t increasing: true when a measurement is taken at t (also inside a dropout). A caller
  /// that skipped slots gets one measurement, the rest are gone.
  bool sample(double t);
  /// A stamp inside the dropout window (measured but never delivered).
  bool inDropout(double stamp) const;

 private:
  FixParams params_;
  double t0_ = 0.0;
  std::int64_t next_ = 0;  // index of the next slot: due at t0 + next_ / rate
};

class PositionFixSensor {
 public:
  /// Throws std::invalid_argument for invalid params.
  explicit PositionFixSensor(const SensorParams& params);
  /// First sample at t0; re-seed, forget pending measurements.
  void reset(double t0 = 0.0);
  /// The true pose at time t (call every step, t increasing): takes a measurement when one is due.
  /// Returns true when it did (also inside a dropout, where the measurement is then lost).
  bool sample(double t, const Pose2D& truth);
  /// The measurements delivered by time t (stamp + latency <= t), oldest first; each is returned once. The
  /// vector is the sensor's own, valid until the next call (reused: no allocation per call).
  const std::vector<FixMeasurement>& due(double t);
  /// A stamp inside the dropout window.
  bool inDropout(double stamp) const { return schedule_.inDropout(stamp); }
  std::size_t pending() const { return pending_.size(); }

  /// SensorSuite's reading: the first sample at time 0 on the start state, then sample() every step.
  void start(const State& s) {
    reset(0.0);
    sample(0.0, {s[X], s[Y], s[THETA]});
  }
  void read(double t, const State& s, double) { sample(t, {s[X], s[Y], s[THETA]}); }

 private:
  SensorParams params_;
  FixSchedule schedule_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::deque<FixMeasurement> pending_;
  std::vector<FixMeasurement> due_;  // due()'s result
};

/// The sensors the plant carries, in the order SensorSuite starts and reads them.
using PlantSensorSet = std::tuple<EncoderOdometry, YawRateSensor, PositionFixSensor>;

}  // namespace core
}  // namespace sowing_robot
