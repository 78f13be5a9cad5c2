// The plant's Gaussian wheel-torque noise: standard normal draws of std::normal_distribution over
// std::mt19937_64, started again from the seed at every plant reset.
#pragma once

#include <cstdint>
#include <random>

namespace sowing_robot {
namespace core {

class TorqueNoise {
 public:
  explicit TorqueNoise(std::uint64_t seed = 1) : engine_(seed) {}

  /// Back to the start of the sequence of `seed`.
  void seed(std::uint64_t seed) {
    engine_.seed(seed);
    normal_.reset();
  }

  /// The next standard normal draw.
  double next() { return normal_(engine_); }

 private:
  std::mt19937_64 engine_;
  std::normal_distribution<double> normal_;
};

}  // namespace core
}  // namespace sowing_robot
