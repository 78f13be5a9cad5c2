// SPDX-License-Identifier: LGPL-2.1-or-later
// (This file only: it reproduces the GNU C Library's cbrt, see below; the rest of the package is BSD.)
//
// The real cube root of the terminal sliding surface, inline and to the bit the value of std::cbrt on
// Debian 12 (glibc 2.36), so that no published number moves: two calls per control period were ~12 %
// of a benchmark run, most of it not the arithmetic but glibc's calls to frexp and ldexp and their
// handling of cases the surface never produces (perf report, docs/performance.md).
//
// It is glibc's algorithm (sysdeps/ieee754/dbl-64/s_cbrt.c, contributed by Ulrich Drepper, 1997;
// Copyright (C) the Free Software Foundation; LGPL-2.1-or-later, hence this file's licence):
// a degree-6 polynomial start u on the mantissa xm in [0.5, 1), one Halley step
// u (u^3 + 2 xm) / (2 u^3 + xm), times 2^((e mod 3) / 3), scaled by 2^(e / 3). The coefficients are those
// of that file, written as hexadecimal floats read from libm.so.6. Only frexp and ldexp are replaced, by
// exponent-field arithmetic that is exact here: a normal |x| = xm 2^e (others go to std::cbrt) has e in
// [-1021, 1024], so |e / 3| <= 341, and ym in [0.5, 2) scaled by 2^(e / 3) stays a normal number.
// test_sliding_mode's CubeRoot.SameBitsAsTheCLibrary compares it with std::cbrt bit for bit over every
// exponent and the surface's range; on a C library with another cbrt that test fails, and the surface
// should then call std::cbrt.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace sowing_robot {
namespace core {

inline double cubeRoot(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const int biased_exponent = static_cast<int>((bits >> 52) & 0x7ff);
  if (biased_exponent == 0 || biased_exponent == 0x7ff) return std::cbrt(x);  // +-0, subnormal, inf, NaN
  // frexp(|x|): |x| = xm 2^e with xm in [0.5, 1)
  const int e = biased_exponent - 1022;
  const std::uint64_t mantissa_bits = (bits & 0x000fffffffffffffULL) | (std::uint64_t{1022} << 52);
  double xm;
  std::memcpy(&xm, &mantissa_bits, sizeof xm);
  // s_cbrt.c's expression, in its order of operations (baseline x86-64: no FMA contraction).
  const double u = 0x1.6b69cba168ff2p-2 +
                   (0x1.8218dde9028b4p+0 +
                    (-0x1.0eb8277cd8d5dp+1 +
                     (0x1.39350adad51ecp+1 +
                      (-0x1.d5ae6cfa20f0cp+0 + (0x1.91e2a6fe7e984p-1 - 0x1.29801e893366dp-3 * xm) * xm) * xm) *
                         xm) *
                        xm) *
                       xm;
  const double t2 = u * u * u;
  // 2^(-2/3), 2^(-1/3), 1, 2^(1/3), 2^(2/3), indexed by 2 + e % 3 (C's remainder: -2..2)
  static constexpr double kFactor[5] = {0x1.428a2f98d728ap-1, 0x1.965fea53d6e3cp-1, 1.0, 0x1.428a2f98d728bp+0,
                                        0x1.965fea53d6e3dp+0};
  const double ym = u * (t2 + 2.0 * xm) / (2.0 * t2 + xm) * kFactor[2 + e % 3];
  const double signed_ym = x > 0.0 ? ym : -ym;
  // ldexp(signed_ym, e / 3): add to the exponent field (exact, see above)
  std::uint64_t result_bits;
  std::memcpy(&result_bits, &signed_ym, sizeof result_bits);
  result_bits += static_cast<std::uint64_t>(static_cast<std::int64_t>(e / 3)) << 52;
  double result;
  std::memcpy(&result, &result_bits, sizeof result);
  return result;
}

}  // namespace core
}  // namespace sowing_robot
