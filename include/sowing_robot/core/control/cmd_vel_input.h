// Velocity commands (cmd_vel twists) in time, turned into what the inner loop is given: each accepted
// command acts from its stamp until the next one, or until cmd_vel_timeout after its stamp, when the
// target becomes zero (a stale command ramps the robot to a stop); the VelocityLimiter moves v and omega
// towards the target in force, switching exactly at those instants. So the desired velocity at t depends
// on the commands stamped before t only, and a run is a function of its stamped commands: in lockstep
// it repeats bit for bit, and a refused command (non-finite, beyond the limits) changes nothing.
//
// Times are integer nanoseconds of simulated time (ros::Time::toNSec()), so that stamps compare exactly.
#pragma once

#include <cstdint>
#include <deque>
#include <string>

#include "sowing_robot/core/common/param_table.h"
#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/control/velocity_limiter.h"

namespace sowing_robot {
namespace core {

/// Defaults, ranges and units: table().
struct CmdVelParams {
  CmdVelParams();
  double timeout;  ///< cmd_vel_timeout [s]; 0 = a command never goes stale
  VelocityLimits limits;
  std::string validate() const { return table().checkRanges(*this); }
  /// cmd_vel_timeout and the limits (velocityLimitsTable()).
  static const ParamTable<CmdVelParams>& table();
};

/// What became of an offered command.
enum class CmdVerdict {
  accepted,
  non_finite,    ///< v or omega is NaN or infinite
  out_of_range,  ///< |v| or |omega| beyond its max_velocity
  late,          ///< strict: stamped before the time already computed
  out_of_order,  ///< stamped before an accepted command
  full,          ///< kMaxQueued commands wait already
};
/// "accepted", "non-finite", "beyond the velocity limits", ...
const char* verdictText(CmdVerdict v);

class CmdVelInput {
 public:
  /// Commands stamped this far ahead are held at most.
  static constexpr std::size_t kMaxQueued = 100000;

  /// strict (lockstep): a command stamped before the time already computed is refused as late.
  /// Otherwise (realtime) it acts from that time on; its stamp still dates it for the timeout.
  /// Throws std::invalid_argument when the parameters do not validate.
  CmdVelInput(const CmdVelParams& params, bool strict);

  /// A command (v [m/s], omega [rad/s]) stamped `stamp` [ns]. Refused ones change nothing.
  CmdVerdict offer(std::int64_t stamp, double v, double omega);
  /// Advances to t [ns] and returns the desired velocity there. The first call starts the clock at t (at
  /// rest); a t not after the time already computed returns the current output unchanged.
  VelocityCommand update(std::int64_t t);
  /// The output at now() (at rest before the first update()).
  VelocityCommand command() const { return limiter_.command(); }

  /// Lockstep's pairing: a command stamped t or later has been accepted, so no command that could still
  /// come changes the output at t (the commands stamped before t are all in).
  bool knownUntil(std::int64_t t) const { return any_ && newest_ >= t; }
  bool started() const { return started_; }
  /// The time computed so far [ns] (0 before the first update()).
  std::int64_t now() const { return now_; }
  /// The command in force at now() has passed cmd_vel_timeout: the target is zero.
  bool stale() const;
  /// Seconds from the stamp of the command in force to now() (0 without one).
  double age() const;
  const CmdVelParams& params() const { return params_; }

 private:
  struct Command {
    std::int64_t stamp, acts_from;
    double v, omega;
  };
  /// Takes the commands acting by now_ into current_.
  void absorb();

  CmdVelParams params_;
  bool strict_;
  std::int64_t timeout_ns_;  // 0: never stale
  VelocityLimiter limiter_;
  std::deque<Command> queued_;  // accepted, not acting yet; acts_from non-decreasing
  Command current_{};
  bool has_current_ = false, any_ = false, started_ = false;
  std::int64_t newest_ = 0, now_ = 0;
};

}  // namespace core
}  // namespace sowing_robot
