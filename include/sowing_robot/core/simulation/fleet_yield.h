// The fleet's yield rule at run time: the plan keeps the robots apart (fleet_split.h), this keeps them apart when
// they run late or early against it. Given every robot's pose and progress at one stamp, a robot holds (stops where
// it is) while a robot of higher priority is within the safety distance, and goes on once every one of them is
// farther than the safety distance plus a hysteresis (so it does not chatter at the edge).
//
// Priority: a strict order, so of any robots close to each other the first never holds and at least one moves (no
// deadlock: the rule cannot stop every robot of a group; the first's hold condition is empty). Robots driving their
// plan come first, by the plan's rank (RobotShare::rank: the block earlier in route order first, the robot that
// enters the other's stretch later is the later one in the plan); then the robots that are not driving (waiting
// for their planned start, or finished), by rank: they stand still anyway, so a driving robot never holds for one
// (a held robot would otherwise wait for a parked one forever). Pure and deterministic: the holds depend only on
// the states given and the holds returned before.
#pragma once

#include <string>
#include <vector>

namespace sowing_robot {
namespace core {

class FleetYield {
 public:
  struct State {
    double x = 0.0, y = 0.0;  ///< [m]
    double progress = 0.0;    ///< share of its route driven, [0, 1]; >= 1: finished
    bool started = true;      ///< its planned wait is over
  };
  /// rank[i]: robot i's place in the plan (distinct; 0 first). Throws std::invalid_argument for fewer than two
  /// robots, ranks that are not distinct, safety_distance not > 0 or hysteresis < 0.
  FleetYield(std::vector<int> rank, double safety_distance, double hysteresis);

  /// The holds at this stamp (true: stop), one state per robot. Throws std::invalid_argument for a wrong count
  /// or a non-finite position.
  const std::vector<bool>& update(const std::vector<State>& states);
  const std::vector<bool>& holds() const { return hold_; }
  /// Robot i's priority at the last update: 0 first.
  int priority(int i) const { return priority_[i]; }
  void reset();

 private:
  std::vector<int> rank_;
  double safety_, hysteresis_;
  std::vector<bool> hold_;
  std::vector<int> priority_;
};

}  // namespace core
}  // namespace sowing_robot
