// Conversions and finiteness checks shared by the nodes.
#pragma once

#include <geometry_msgs/Quaternion.h>
#include <nav_msgs/Odometry.h>
#include <ros/time.h>

#include <cmath>
#include <cstdint>

#include "sowing_robot/core/common/types.h"

namespace sowing_robot {

/// Planar pose from odometry. The yaw comes from the quaternion exactly as core::yawThroughQuaternion
/// reconstructs it, so nodes and the in-process runner agree bit for bit.
inline core::Pose2D poseOf(const nav_msgs::Odometry& o) {
  const auto& q = o.pose.pose.orientation;
  return {o.pose.pose.position.x, o.pose.pose.position.y, std::atan2(2.0 * q.w * q.z, 1.0 - 2.0 * q.z * q.z)};
}

/// A stamp as the in-process loop's time of that period (core::secondsFromNanos of its nanoseconds), so a time
/// compared or stored by a node is the same double as in the in-process runner (ros::Time::toSec can differ in the
/// last bit).
inline double loopSeconds(const ros::Time& stamp) {
  return core::secondsFromNanos(static_cast<std::int64_t>(stamp.toNSec()));
}

/// The quaternion of a yaw about z, as core::yawThroughQuaternion builds it (poseOf inverts it).
inline geometry_msgs::Quaternion yawQuaternion(double theta) {
  geometry_msgs::Quaternion q;
  q.z = std::sin(0.5 * theta);
  q.w = std::cos(0.5 * theta);
  return q;
}

/// True when every field the controllers use is finite.
inline bool odomIsFinite(const nav_msgs::Odometry& o) {
  const auto& q = o.pose.pose.orientation;
  return core::allFinite(o.pose.pose.position.x, o.pose.pose.position.y, q.z, q.w, o.twist.twist.linear.x,
                         o.twist.twist.angular.z);
}

}  // namespace sowing_robot

namespace sowing_robot {
/// Publisher and subscriber queue of every per-period topic: a recorder that falls behind in lockstep
/// (which does not wait for it) must not lose messages, so the queue holds several seconds of a 1 kHz
/// run; and a subscriber in a nodelet manager gets the reference generator's lookahead in one burst
/// (50 references at the defaults), which a short queue would cut (dropping the oldest, the one due).
/// The recorded topics that are not per period (seeds, joint_states, fix, wheel_slip) use it too: a
/// publisher's queue is per subscriber, and a short one dropped the oldest of them before a lagging recorder
/// read them (a loaded fleet run recorded 77 of 88 seed messages).
constexpr std::uint32_t kLockstepQueue = 20000;
}  // namespace sowing_robot

#include <ros/publisher.h>
#include <boost/make_shared.hpp>

namespace sowing_robot {
/// Publish a copy as a shared pointer: inside a nodelet manager subscribers get the pointer itself
/// (no serialisation); to other processes it is serialised as usual.
template <typename M>
void publishShared(const ros::Publisher& pub, const M& msg) {
  pub.publish(boost::make_shared<M>(msg));
}
}  // namespace sowing_robot
