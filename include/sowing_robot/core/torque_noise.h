// The plant's Gaussian torque noise: the numbers of std::normal_distribution<double>(0, 1) over
// std::mt19937_64 as GCC's libstdc++ draws them (Marsaglia's polar method over generate_canonical), to
// the bit and in the same order, but cheaper in the closed loop, where it was ~20 % of a noisy run:
//  - drawn in blocks of kBlock: the polar method's rejection test (taken ~21 % of the time, at random)
//    mispredicts inside a short loop of its own instead of in the middle of a control period, where each
//    miss threw away the period's work in flight; the values are the same, only drawn earlier;
//  - inline, and the 64-bit unsigned to double conversion without the branch GCC emits for it
//    (u >= 2^63 in half the draws, at random).
// test_plant's TorqueNoise.SameNumbersAsTheStandardLibrary compares it with std::normal_distribution.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace sowing_robot {
namespace core {

class TorqueNoise {
 public:
  static constexpr int kBlock = 64;

  explicit TorqueNoise(std::uint64_t seed = 1) : engine_(seed) {}

  /// Back to the start of the sequence of `seed` (std::mt19937_64::seed and normal_distribution::reset).
  void seed(std::uint64_t seed) {
    engine_.seed(seed);
    saved_available_ = false;
    next_ = kBlock;
  }

  /// The next standard normal draw.
  double next() {
    if (next_ == kBlock) refill();
    return block_[next_++];
  }

 private:
  void refill() {
    for (double& v : block_) v = polar();
    next_ = 0;
  }

  // generate_canonical<double, 53>(engine): one 64-bit draw (max - min + 1 = 2^64), divided by 2^64.
  double canonical() {
    const std::uint64_t u = engine_();
    // double(u) rounded to nearest: both 32-bit halves convert exactly and the sum rounds once, so this
    // is the correctly rounded value that the standard conversion gives, without its branch.
    const double d = static_cast<double>(static_cast<std::int64_t>(u >> 32)) * 0x1p32 +
                     static_cast<double>(static_cast<std::int64_t>(u & 0xffffffffULL));
    const double r = d * 0x1p-64;                // sum / 2^64: exact
    return r >= 1.0 ? 0x1.fffffffffffffp-1 : r;  // nextafter(1, 0) when u rounds up to 2^64
  }

  // normal_distribution<double>::operator() with mean 0, stddev 1: one polar pair, the second value
  // saved for the next call.
  double polar() {
    if (saved_available_) {
      saved_available_ = false;
      return saved_ * 1.0 + 0.0;  // ret * stddev + mean, as the library returns it (+0.0 turns -0 into 0)
    }
    double x, y, r2;
    do {
      x = 2.0 * canonical() - 1.0;
      y = 2.0 * canonical() - 1.0;
      r2 = x * x + y * y;
    } while (r2 > 1.0 || r2 == 0.0);
    const double mult = std::sqrt(-2 * std::log(r2) / r2);
    saved_ = x * mult;
    saved_available_ = true;
    return (y * mult) * 1.0 + 0.0;
  }

  std::mt19937_64 engine_;
  bool saved_available_ = false;
  double saved_ = 0.0;
  int next_ = kBlock;  // kBlock: the block is used up (or never drawn)
  double block_[kBlock] = {};
};

}  // namespace core
}  // namespace sowing_robot
