// Plain data passed between the core blocks (and mirrored one-to-one by the ROS messages).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

namespace sowing_robot {
namespace core {

/// Planar posture of the axle midpoint [m, m, rad].
struct Pose2D {
  double x = 0.0, y = 0.0, theta = 0.0;
};

/// Reference posture with the velocities and accelerations the controllers need.
struct Reference {
  Pose2D pose;
  double v = 0.0;          ///< [m/s]
  double omega = 0.0;      ///< [rad/s]
  double v_dot = 0.0;      ///< [m/s^2]
  double omega_dot = 0.0;  ///< [rad/s^2]
  bool tool_down = true;   ///< on a sowing row
  /// A stop hold: the plan keeps the robot at rest here (its end, a stop short of an obstacle). The outer
  /// controllers then command the hold (holdCommand()) instead of chasing the pose.
  bool stop = false;
};

/// Output of the kinematic controller.
struct VelocityCommand {
  double v = 0.0, omega = 0.0;          ///< [m/s], [rad/s]
  double v_dot = 0.0, omega_dot = 0.0;  ///< [m/s^2], [rad/s^2]
  /// Hold the robot at rest (a stop): the inner loop brakes the wheels with its own states frozen
  /// (standstill_hold.h); v, omega and their derivatives are then 0.
  bool hold = false;
};

/// The outer loop's answer to a stop hold: zero velocities, and the hold for the inner loop. A robot that
/// cannot move sideways cannot remove a lateral error at rest, so a stop chases no pose.
inline VelocityCommand holdCommand() {
  VelocityCommand c;
  c.hold = true;
  return c;
}

/// Wheel torques [N·m].
struct WheelTorques {
  double right = 0.0, left = 0.0;
};

/// Wrap an angle to (-pi, pi].
inline double wrapAngle(double a) {
  if (a > -M_PI && a <= M_PI) return a;  // what remainder() returns here anyway, without its cost
  a = std::remainder(a, 2.0 * M_PI);
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

/// Seconds of a nanosecond count, computed exactly as ros::Time::toSec() does, so that the in-process
/// runner and the node pipeline see bit-identical times.
inline double secondsFromNanos(std::int64_t ns) {
  return static_cast<double>(ns / 1000000000) + 1e-9 * static_cast<double>(ns % 1000000000);
}

/// The yaw that survives a trip through a geometry_msgs quaternion (z = sin(t/2), w = cos(t/2)) and
/// back, so that the runner sees what the nodes see in nav_msgs/Odometry.
inline double yawThroughQuaternion(double theta) {
  double z, w;
  z = std::sin(0.5 * theta);
  w = std::cos(0.5 * theta);
  return std::atan2(2.0 * w * z, 1.0 - 2.0 * z * z);
}

/// (cos h, sin h): the unit vector of heading h.
inline Eigen::Vector2d unitVector(double heading) { return {std::cos(heading), std::sin(heading)}; }

/// The closest point of segment a-b to p, as its parameter u in [0, 1] (the point a + u (b - a)); 0 when a == b.
inline double segmentParameter(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  return len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
}

/// True when every argument is a finite number.
template <typename... T>
bool allFinite(T... v) {
  return (std::isfinite(v) && ...);
}

}  // namespace core
}  // namespace sowing_robot
