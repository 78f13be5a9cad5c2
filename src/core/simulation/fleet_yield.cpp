#include "sowing_robot/core/simulation/fleet_yield.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace sowing_robot {
namespace core {

FleetYield::FleetYield(std::vector<int> rank, double safety_distance, double hysteresis)
    : rank_(std::move(rank)), safety_(safety_distance), hysteresis_(hysteresis) {
  if (rank_.size() < 2) throw std::invalid_argument("FleetYield: at least two robots are needed");
  std::vector<int> sorted = rank_;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    throw std::invalid_argument("FleetYield: the ranks must be distinct");
  if (!(safety_distance > 0.0) || !std::isfinite(safety_distance))
    throw std::invalid_argument("FleetYield: safety_distance must be > 0");
  if (!(hysteresis >= 0.0) || !std::isfinite(hysteresis))
    throw std::invalid_argument("FleetYield: hysteresis must be >= 0");
  reset();
}

void FleetYield::reset() {
  hold_.assign(rank_.size(), false);
  priority_.resize(rank_.size());
  std::iota(priority_.begin(), priority_.end(), 0);
}

const std::vector<bool>& FleetYield::update(const std::vector<State>& states) {
  const std::size_t n = rank_.size();
  if (states.size() != n) throw std::invalid_argument("FleetYield: one state per robot is needed");
  for (const State& s : states)
    if (!std::isfinite(s.x) || !std::isfinite(s.y)) throw std::invalid_argument("FleetYield: non-finite position");
  // The order: driving robots by rank, then the others by rank (a strict order: ranks are distinct).
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](int i) {
    const bool driving = states[i].started && states[i].progress < 1.0;
    return std::pair<int, int>{driving ? 0 : 1, rank_[i]};
  };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
  for (std::size_t p = 0; p < n; ++p) priority_[order[p]] = static_cast<int>(p);
  std::vector<bool> next(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    // Held: released only beyond the safety distance plus the hysteresis; else held within the safety distance.
    const double reach = hold_[i] ? safety_ + hysteresis_ : safety_;
    for (std::size_t j = 0; j < n && !next[i]; ++j)
      if (priority_[j] < priority_[i] && std::hypot(states[i].x - states[j].x, states[i].y - states[j].y) < reach)
        next[i] = true;
  }
  hold_ = std::move(next);
  return hold_;
}

}  // namespace core
}  // namespace sowing_robot
