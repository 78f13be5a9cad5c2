// MT19937-64 (Matsumoto & Nishimura 2000; the parameters of std::mt19937_64, [rand.predef]): the same
// sequence as the standard engine for every seed, for the plant's torque noise (torque_noise.h).
// libstdc++'s twist tests each word's low bit with a branch, and that bit is random: about one
// misprediction every two numbers, ~5 % of a benchmark run (perf). Here the twist is branchless
// (the matrix A is applied as a mask of the low bit). test_plant's Mt19937_64 tests compare it with
// std::mt19937_64.
#pragma once

#include <cstdint>

namespace sowing_robot {
namespace core {

class Mt19937_64 {
 public:
  explicit Mt19937_64(std::uint64_t seed = kDefaultSeed) { this->seed(seed); }

  /// std::mt19937_64::seed(value): the standard's initialisation, x_i = f (x_{i-1} ^ (x_{i-1} >> 62)) + i.
  void seed(std::uint64_t value) {
    state_[0] = value;
    for (int i = 1; i < kN; ++i)
      state_[i] = kF * (state_[i - 1] ^ (state_[i - 1] >> 62)) + static_cast<std::uint64_t>(i);
    index_ = kN;
  }

  /// The next number (the standard engine's operator()).
  std::uint64_t operator()() {
    if (index_ == kN) twist();
    std::uint64_t y = state_[index_++];
    y ^= (y >> 29) & 0x5555555555555555ULL;
    y ^= (y << 17) & 0x71d67fffeda60000ULL;
    y ^= (y << 37) & 0xfff7eee000000000ULL;
    return y ^ (y >> 43);
  }

  static constexpr std::uint64_t kDefaultSeed = 5489u;

 private:
  static constexpr int kN = 312, kM = 156;
  static constexpr std::uint64_t kF = 6364136223846793005ULL;
  static constexpr std::uint64_t kLower = (std::uint64_t{1} << 31) - 1, kUpper = ~kLower;

  // x_{i+n} = x_{i+m} ^ ((upper(x_i) | lower(x_{i+1})) A), A: a shift right and, when the low bit is
  // set, an exclusive or with a. In place, in the two ranges where x_{i+m} is an old word and a new one.
  static std::uint64_t mix(std::uint64_t current, std::uint64_t next, std::uint64_t ahead) {
    const std::uint64_t x = (current & kUpper) | (next & kLower);
    return ahead ^ (x >> 1) ^ ((0 - (x & 1)) & 0xb5026f5aa96619e9ULL);
  }
  void twist() {
    for (int i = 0; i < kN - kM; ++i) state_[i] = mix(state_[i], state_[i + 1], state_[i + kM]);
    for (int i = kN - kM; i < kN - 1; ++i) state_[i] = mix(state_[i], state_[i + 1], state_[i + kM - kN]);
    state_[kN - 1] = mix(state_[kN - 1], state_[0], state_[kM - 1]);
    index_ = 0;
  }

  std::uint64_t state_[kN];
  int index_ = kN;
};

}  // namespace core
}  // namespace sowing_robot
