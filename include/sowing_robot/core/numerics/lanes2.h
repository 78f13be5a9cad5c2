// Two doubles in one SSE2 register, with the arithmetic operators, for stepping two independent runs
// in one instruction stream (Plant::stepPair; the benchmark's Monte-Carlo runs, docs/performance.md).
// Each packed instruction (addpd, subpd, mulpd, divpd) rounds every lane exactly as the scalar one
// (addsd, ...) rounds its operand: code templated over the number type gives each lane, to the bit,
// the numbers the double instantiation gives. Nothing here fuses or reorders operations.
// kHaveLanes2 is false where SSE2 is not available (non-x86 builds): callers then step lane by lane.
#pragma once

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace sowing_robot {
namespace core {

#if defined(__SSE2__)
constexpr bool kHaveLanes2 = true;

struct Lanes2 {
  __m128d v;

  Lanes2() = default;
  /// The same value in both lanes.
  explicit Lanes2(double both) : v(_mm_set1_pd(both)) {}
  Lanes2(double first, double second) : v(_mm_set_pd(second, first)) {}
  explicit Lanes2(__m128d packed) : v(packed) {}

  double first() const { return _mm_cvtsd_f64(v); }
  double second() const { return _mm_cvtsd_f64(_mm_unpackhi_pd(v, v)); }
};

inline Lanes2 operator+(Lanes2 a, Lanes2 b) { return Lanes2(_mm_add_pd(a.v, b.v)); }
inline Lanes2 operator-(Lanes2 a, Lanes2 b) { return Lanes2(_mm_sub_pd(a.v, b.v)); }
inline Lanes2 operator*(Lanes2 a, Lanes2 b) { return Lanes2(_mm_mul_pd(a.v, b.v)); }
inline Lanes2 operator/(Lanes2 a, Lanes2 b) { return Lanes2(_mm_div_pd(a.v, b.v)); }
/// Negation flips the sign bit, as the scalar -x does (xorpd with -0.0).
inline Lanes2 operator-(Lanes2 a) { return Lanes2(_mm_xor_pd(a.v, _mm_set1_pd(-0.0))); }
#else
constexpr bool kHaveLanes2 = false;
#endif

}  // namespace core
}  // namespace sowing_robot
