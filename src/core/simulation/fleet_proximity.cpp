#include "sowing_robot/core/simulation/fleet_proximity.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "sowing_robot/core/common/types.h"

namespace sowing_robot {
namespace core {

FleetProximity::FleetProximity(int robots, double safety_distance)
    : safety_(safety_distance), closest_(std::numeric_limits<double>::infinity()) {
  if (robots < 2) throw std::invalid_argument("a fleet needs at least 2 robots, not " + std::to_string(robots));
  if (!(safety_distance > 0.0) || !std::isfinite(safety_distance))
    throw std::invalid_argument("safety_distance must be a finite number > 0");
  queues_.resize(static_cast<std::size_t>(robots));
  open_.assign(static_cast<std::size_t>(robots * robots), -1);
}

std::size_t FleetProximity::pending() const {
  std::size_t n = 0;
  for (const auto& q : queues_) n += q.size();
  return n;
}

std::vector<FleetProximity::Encounter> FleetProximity::add(int robot, std::int64_t stamp_ns, double x, double y) {
  std::vector<Encounter> begun;
  if (robot < 0 || robot >= static_cast<int>(queues_.size()) || !allFinite(x, y)) return begun;
  auto& own = queues_[static_cast<std::size_t>(robot)];
  if (!own.empty() && stamp_ns <= own.back().stamp_ns) return begun;  // a repeat or out of order: ignored
  own.push_back(Sample{stamp_ns, x, y});
  // Compare every stamp all robots have reached; a stamp some robot skipped (it never comes) is dropped.
  for (;;) {
    std::int64_t latest_front = std::numeric_limits<std::int64_t>::min();
    for (const auto& q : queues_) {
      if (q.empty()) return begun;
      latest_front = std::max(latest_front, q.front().stamp_ns);
    }
    bool aligned = true;
    for (auto& q : queues_) {
      while (!q.empty() && q.front().stamp_ns < latest_front) q.pop_front();
      if (q.empty()) return begun;
      aligned = aligned && q.front().stamp_ns == latest_front;
    }
    if (!aligned) continue;
    std::vector<Sample> at;
    for (auto& q : queues_) {
      at.push_back(q.front());
      q.pop_front();
    }
    for (const Encounter& e : compare(latest_front, at)) begun.push_back(e);
  }
}

std::vector<FleetProximity::Encounter> FleetProximity::compare(std::int64_t stamp_ns, const std::vector<Sample>& at) {
  std::vector<Encounter> begun;
  const double t = secondsFromNanos(stamp_ns);
  const int n = static_cast<int>(at.size());
  ++compared_;
  last_ns_ = stamp_ns;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      const double d = std::hypot(at[a].x - at[b].x, at[a].y - at[b].y);
      if (d < closest_) closest_ = d, closest_a_ = a, closest_b_ = b, closest_t_ = t;
      int& open = open_[static_cast<std::size_t>(a * n + b)];
      if (d < safety_) {
        if (open < 0) {
          encounters_.push_back(Encounter{a, b, t, t, d, true});
          open = static_cast<int>(encounters_.size()) - 1;
          begun.push_back(encounters_.back());
        }
        Encounter& e = encounters_[static_cast<std::size_t>(open)];
        e.end = t;
        e.min_distance = std::min(e.min_distance, d);
      } else if (open >= 0) {
        encounters_[static_cast<std::size_t>(open)].open = false;
        open = -1;
      }
    }
  }
  return begun;
}

}  // namespace core
}  // namespace sowing_robot
