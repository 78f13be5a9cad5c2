// The fleet's safety check: every pair of robots' positions at the same stamp, their closest approach, and
// each stretch of time a pair spends closer than a safety distance. Robots of a fleet run lockstep loops of
// their own, so their states arrive at different wall times; they are compared by stamp, so the report does
// not depend on which robot ran ahead.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace sowing_robot {
namespace core {

class FleetProximity {
 public:
  /// A pair closer than the safety distance, from `begin` until `end` (the last stamp it was still within).
  struct Encounter {
    int a = 0, b = 0;               ///< robot indices, a < b
    double begin = 0.0, end = 0.0;  ///< [s]
    double min_distance = 0.0;      ///< [m] closest during it
    bool open = true;               ///< still within at the last stamp compared
  };
  /// Throws std::invalid_argument for robots < 2 or safety_distance not > 0.
  FleetProximity(int robots, double safety_distance);

  /// Robot `robot`'s position at stamp_ns (stamps of one robot increase). Returns the encounters that began
  /// with the stamps this completed (every robot's position known), for the caller to report.
  std::vector<Encounter> add(int robot, std::int64_t stamp_ns, double x, double y);

  double closest() const { return closest_; }  ///< [m] over every compared stamp (+inf before any)
  int closestA() const { return closest_a_; }
  int closestB() const { return closest_b_; }
  double closestTime() const { return closest_t_; }       ///< [s]
  std::int64_t compared() const { return compared_; }     ///< stamps with every robot's position
  std::int64_t lastCompared() const { return last_ns_; }  ///< the last of them [ns] (-1 before any)
  const std::vector<Encounter>& encounters() const { return encounters_; }
  /// States waiting for the other robots' of the same stamp (a robot that ran ahead).
  std::size_t pending() const;

 private:
  struct Sample {
    std::int64_t stamp_ns;
    double x, y;
  };
  std::vector<Encounter> compare(std::int64_t stamp_ns, const std::vector<Sample>& at);

  double safety_;
  std::vector<std::deque<Sample>> queues_;
  std::vector<int> open_;  ///< per pair (a * robots + b): index into encounters_, or -1
  std::vector<Encounter> encounters_;
  double closest_;
  int closest_a_ = -1, closest_b_ = -1;
  double closest_t_ = 0.0;
  std::int64_t compared_ = 0;
  std::int64_t last_ns_ = -1;
};

}  // namespace core
}  // namespace sowing_robot
