// The plant's Gaussian torque noise: the numbers of std::normal_distribution<double>(0, 1) over
// std::mt19937_64 as GCC's libstdc++ draws them (Marsaglia's polar method over generate_canonical), to
// the bit and in the same order, but cheaper in the closed loop, where it was ~20 % of a noisy run:
//  - the engine is Mt19937_64 (mt19937_64.h), the standard engine's sequence with a branchless twist;
//  - drawn in blocks of kBlock: the polar method's rejection test (taken ~21 % of the time, at random)
//    mispredicts inside a short loop of its own instead of in the middle of a control period, where each
//    miss threw away the period's work in flight; the values are the same, only drawn earlier; and
//    within a block the rejection is an index that advances or not, not a branch (refill());
//  - inline, and the 64-bit unsigned to double conversion without the branch GCC emits for it
//    (u >= 2^63 in half the draws, at random).
// test_plant's TorqueNoise.SameNumbersAsTheStandardLibrary compares it with std::normal_distribution.
#pragma once

#include <cmath>
#include <cstdint>

#include "sowing_robot/core/numerics/mt19937_64.h"

namespace sowing_robot {
namespace core {

class TorqueNoise {
 public:
  static constexpr int kBlock = 64;

  explicit TorqueNoise(std::uint64_t seed = 1) : engine_(seed) {}

  /// Back to the start of the sequence of `seed` (std::mt19937_64::seed and normal_distribution::reset).
  void seed(std::uint64_t seed) {
    engine_.seed(seed);
    next_ = kBlock;
  }

  /// The next standard normal draw.
  double next() {
    if (next_ == kBlock) refill();
    return block_[next_++];
  }

 private:
  static constexpr int kPairs = kBlock / 2;  // a block is whole polar pairs (kBlock even): no value saved across

  // kPairs polar pairs in two passes (the same draws, the same operations, the same order of values as
  // normal_distribution: y * mult, then the saved x * mult):
  //  1. the candidates (x, y) in draw order, each written at the next free slot and kept (the slot
  //     advanced) when inside the unit circle: the rejection is an add, not a branch that mispredicts
  //     about one time in five;
  //  2. log, division and sqrt of the kept ones: independent of each other, so they overlap.
  // Out of line (once per kBlock / 2 steps), so that the step that draws stays small enough to inline.
#if defined(__GNUC__)
  __attribute__((noinline))
#endif
  void
  refill() {
    int n = 0;
    while (n < kPairs) {
      const double x = 2.0 * canonical() - 1.0;
      const double y = 2.0 * canonical() - 1.0;
      const double r2 = x * x + y * y;
      x_[n] = x;
      y_[n] = y;
      r2_[n] = r2;
      n += static_cast<int>(!((r2 > 1.0) | (r2 == 0.0)));
    }
    for (int j = 0; j < kPairs; ++j) {
      const double mult = std::sqrt(-2 * std::log(r2_[j]) / r2_[j]);
      // ret * stddev + mean, as the library returns both values (+0.0 turns -0 into 0)
      block_[2 * j] = (y_[j] * mult) * 1.0 + 0.0;
      block_[2 * j + 1] = (x_[j] * mult) * 1.0 + 0.0;
    }
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

  Mt19937_64 engine_;
  int next_ = kBlock;  // kBlock: the block is used up (or never drawn)
  double block_[kBlock] = {};
  double x_[kPairs] = {}, y_[kPairs] = {}, r2_[kPairs] = {};  // refill()'s kept candidates
};

}  // namespace core
}  // namespace sowing_robot
