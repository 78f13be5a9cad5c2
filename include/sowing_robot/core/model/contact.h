// Contact detection: the footprint placed at the robot's pose, checked against every obstacle at every
// step. Contacts are only reported (the plant does not model them: the robot drives through the
// obstacle as before, so a run with a contact still ends and its report says when, where and how deep).
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/model/footprint.h"
#include "sowing_robot/core/model/obstacle.h"

namespace sowing_robot {
namespace core {

/// One contact: the body overlapped obstacle `obstacle` from `start` to `end` (while `ongoing`, `end` is
/// the last time seen in contact).
struct ContactEvent {
  std::size_t obstacle = 0;       ///< index into the obstacle list in force when it started
  double start = 0.0, end = 0.0;  ///< [s]
  double max_depth = 0.0;         ///< deepest penetration [m], > 0
  bool ongoing = true;
};

class ContactMonitor {
 public:
  /// Throws std::invalid_argument on an invalid footprint (an empty one checks the axle point) or obstacle.
  ContactMonitor(Footprint footprint, std::vector<Obstacle> obstacles);

  /// Replace the obstacles (run-time list; throws std::invalid_argument). Contacts in progress end at the
  /// last time they were seen.
  void setObstacles(std::vector<Obstacle> obstacles);

  /// The robot at `pose` at time t (non-decreasing). Returns true when a contact started or ended here.
  /// A non-finite pose or time is refused (false, counted by rejected()).
  bool update(double t, const Pose2D& pose);
  /// Ends the contacts in progress (call at the end of the run for the final report).
  void finish();

  const std::vector<ContactEvent>& events() const { return events_; }
  std::size_t contactCount() const { return events_.size(); }
  bool inContact() const;
  /// Smallest signed body clearance over the run [m] (+inf before the first update or without obstacles),
  /// with the obstacle and the time where it was reached.
  double minClearance() const { return min_clearance_; }
  std::size_t minClearanceObstacle() const { return min_obstacle_; }
  double minClearanceTime() const { return min_time_; }
  /// Clearance at the last update [m].
  double clearance() const { return last_clearance_; }
  std::size_t rejected() const { return rejected_; }
  /// Multi-line text: minimum clearance and every contact.
  std::string report() const;

 private:
  void closeAll();

  Footprint footprint_;
  std::vector<Obstacle> obstacles_;
  std::vector<long> open_;  ///< per obstacle: index of its ongoing event in events_, or -1
  std::vector<ContactEvent> events_;
  double min_clearance_ = std::numeric_limits<double>::infinity(), min_time_ = 0.0;
  double last_clearance_ = std::numeric_limits<double>::infinity();
  std::size_t min_obstacle_ = 0, rejected_ = 0;
};

}  // namespace core
}  // namespace sowing_robot
