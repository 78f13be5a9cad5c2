// The fleet's yield rule (fleet_yield.h) on scripted poses: who holds, the hysteresis, and that it never stops
// every robot of a group.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "sowing_robot/core/simulation/fleet_yield.h"

using sowing_robot::core::FleetYield;
using State = FleetYield::State;

TEST(FleetYield, HeadOnTheLaterRobotHoldsUntilTheOtherHasPassed) {
  // Robot 0 (rank 1, later in the plan) and robot 1 (rank 0) on one line towards each other at 0.1 m per stamp; a
  // held robot does not move. Robot 1 drives past robot 0 one metre to the side.
  FleetYield yield({1, 0}, 2.0, 0.5);
  double x0 = -10.0, x1 = 10.0;
  bool held_once = false, released_after = false;
  for (int k = 0; k < 400; ++k) {
    const std::vector<bool>& hold = yield.update({State{x0, 0.0, 0.3, true}, State{x1, 1.0, 0.3, true}});
    ASSERT_FALSE(hold[1]) << "the first in the plan never holds, stamp " << k;
    const double d = std::hypot(x0 - x1, 1.0);
    if (hold[0]) {
      held_once = true;
      EXPECT_LT(d, 2.5 + 1e-9);
    } else {
      if (held_once) released_after = true;
      EXPECT_GE(d, 2.0 - 1e-9) << "a moving later robot is never inside the safety distance of the first";
      x0 += 0.1;
    }
    x1 -= 0.1;
  }
  EXPECT_TRUE(held_once);
  EXPECT_TRUE(released_after);
  EXPECT_GT(x0, 0.0) << "it went on";
}

TEST(FleetYield, HysteresisKeepsTheHoldUntilClearOfTheSafetyDistancePlusIt) {
  FleetYield yield({0, 1}, 2.0, 0.5);
  const double distances[] = {3.0, 1.9, 2.1, 2.4, 2.45, 1.5, 2.49, 2.51, 2.2, 1.99};
  const bool expected[] = {false, true, true, true, true, true, true, false, false, true};
  for (int k = 0; k < 10; ++k) {
    const std::vector<bool>& hold = yield.update({State{0.0, 0.0, 0.5, true}, State{distances[k], 0.0, 0.5, true}});
    EXPECT_FALSE(hold[0]);
    EXPECT_EQ(hold[1], expected[k]) << "distance " << distances[k];
  }
}

TEST(FleetYield, ARobotThatWaitsOrHasFinishedGivesWay) {
  FleetYield yield({0, 1}, 2.0, 0.5);
  // Robot 0 (first in the plan) has finished and stands in robot 1's way: robot 1 goes on, robot 0 "holds".
  std::vector<bool> hold = yield.update({State{0.0, 0.0, 1.0, true}, State{1.0, 0.0, 0.7, true}});
  EXPECT_TRUE(hold[0]);
  EXPECT_FALSE(hold[1]);
  EXPECT_EQ(yield.priority(1), 0);
  // Robot 0 still waits for its planned start: the same.
  yield.reset();
  hold = yield.update({State{0.0, 0.0, 0.0, false}, State{1.0, 0.0, 0.2, true}});
  EXPECT_TRUE(hold[0]);
  EXPECT_FALSE(hold[1]);
  // Both driving: the plan's order.
  hold = yield.update({State{0.0, 0.0, 0.1, true}, State{1.0, 0.0, 0.2, true}});
  EXPECT_FALSE(hold[0]);
  EXPECT_TRUE(hold[1]);
}

TEST(FleetYield, NeverStopsEveryRobotOfAGroup) {
  // Five robots on random walks in a 12 m square (crowded: most stamps have groups within the safety distance),
  // some finished or not started. In every group of robots linked by the release distance, the one of the highest
  // priority moves; every held robot has one of higher priority within the release distance; equal inputs give
  // equal holds.
  const std::vector<int> rank = {3, 0, 4, 1, 2};
  FleetYield yield(rank, 2.0, 0.5), twin(rank, 2.0, 0.5);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> step(-0.3, 0.3), start(0.0, 12.0), coin(0.0, 1.0);
  std::vector<State> s(5);
  for (State& r : s) r = {start(rng), start(rng), 0.5, true};
  int held_stamps = 0;
  for (int k = 0; k < 5000; ++k) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (!yield.holds()[i]) {
        s[i].x = std::clamp(s[i].x + step(rng), 0.0, 12.0);
        s[i].y = std::clamp(s[i].y + step(rng), 0.0, 12.0);
      }
      if (k % 500 == 0) {
        const double c = coin(rng);
        s[i].progress = c < 0.1 ? 1.0 : 0.5;
        s[i].started = c > 0.05;
      }
    }
    const std::vector<bool> hold = yield.update(s);
    ASSERT_EQ(hold, twin.update(s)) << "stamp " << k;
    // Groups: components of the graph "closer than safety + hysteresis".
    const int n = static_cast<int>(s.size());
    std::vector<int> group(n, -1);
    for (int i = 0; i < n; ++i) {
      if (group[i] >= 0) continue;
      std::vector<int> stack = {i};
      group[i] = i;
      while (!stack.empty()) {
        const int a = stack.back();
        stack.pop_back();
        for (int b = 0; b < n; ++b)
          if (group[b] < 0 && std::hypot(s[a].x - s[b].x, s[a].y - s[b].y) < 2.5) {
            group[b] = i;
            stack.push_back(b);
          }
      }
    }
    for (int g = 0; g < n; ++g) {
      int first = -1;
      for (int i = 0; i < n; ++i)
        if (group[i] == g && (first < 0 || yield.priority(i) < yield.priority(first))) first = i;
      if (first >= 0) {
        ASSERT_FALSE(hold[first]) << "stamp " << k << ": the group's first robot holds";
      }
    }
    for (int i = 0; i < n; ++i) {
      if (!hold[i]) continue;
      ++held_stamps;
      bool reason = false;
      for (int j = 0; j < n; ++j)
        reason |= yield.priority(j) < yield.priority(i) && std::hypot(s[i].x - s[j].x, s[i].y - s[j].y) < 2.5;
      ASSERT_TRUE(reason) << "stamp " << k << ": robot " << i << " holds for nobody";
    }
  }
  EXPECT_GT(held_stamps, 1000) << "the walk was crowded enough to test anything";
}

TEST(FleetYield, RefusesBadArguments) {
  EXPECT_THROW(FleetYield({0}, 2.0, 0.5), std::invalid_argument);
  EXPECT_THROW(FleetYield({0, 0}, 2.0, 0.5), std::invalid_argument);
  EXPECT_THROW(FleetYield({0, 1}, 0.0, 0.5), std::invalid_argument);
  EXPECT_THROW(FleetYield({0, 1}, 2.0, -0.1), std::invalid_argument);
  FleetYield y({0, 1}, 2.0, 0.5);
  EXPECT_THROW(y.update({State{}}), std::invalid_argument);
  EXPECT_THROW(y.update({State{NAN, 0.0}, State{}}), std::invalid_argument);
}
