// How still a robot holds at a stop: the figures the standstill-hold tests (test_stop_hold, test_profile_edges)
// judge a hold by, from the true state of every period of it.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "sowing_robot/core/model/plant.h"

namespace sowing_robot::test {

struct HoldMeter {
  double max_v = 0.0, max_omega = 0.0;  ///< largest |v| [m/s] and |omega| [rad/s]
  double drift = 0.0;                   ///< largest distance from the first sampled position [m]
  double max_wheel_rate = 0.0;          ///< largest |wheel spin| over a period, either wheel [rad/s]

  /// One period of the hold: the true state x at time t.
  void sample(double t, const core::State& x) {
    using namespace core;
    const Eigen::Vector2d p(x[X], x[Y]);
    if (!has_settled_) settled_ = p;
    has_settled_ = true;
    max_v = std::max(max_v, std::fabs(x[V]));
    max_omega = std::max(max_omega, std::fabs(x[OMEGA]));
    drift = std::max(drift, (p - settled_).norm());
    // The wheels' spin over each period, from their angles (what an encoder counts).
    if (has_prev_)
      for (int w = 0; w < 2; ++w)
        max_wheel_rate = std::max(max_wheel_rate, std::fabs(x[PHI_R + w] - prev_phi_[w]) / (t - prev_t_));
    has_prev_ = true;
    prev_t_ = t;
    prev_phi_[0] = x[PHI_R];
    prev_phi_[1] = x[PHI_L];
  }

 private:
  Eigen::Vector2d settled_ = Eigen::Vector2d::Zero();
  bool has_settled_ = false, has_prev_ = false;
  double prev_t_ = 0.0, prev_phi_[2] = {0.0, 0.0};
};

}  // namespace sowing_robot::test
