// The package's sine and cosine: every sin and cos of the core and the nodes goes through these, so
// that the in-process runner, the node pipeline and the Python module compute the same bits.
//
// Why not std::sin / std::cos: on the benchmark's line run libm's sincos was ~22 % of the instructions
// of a control period (4.3 calls a period: the yaw, the disturbance at two stage times, the plant's
// heading), most of it not the arithmetic but the call through the PLT, glibc's CPU dispatch and its
// table-driven, correctly-rounded-in-most-cases algorithm, which a closed loop integrated in double does
// not need. These are inline, branch-light and within 1 ulp (fdlibm's bound; test_trig measures the
// error against long double over the arguments the package meets). They differ from glibc's in the last
// bit for ~6 % of arguments, so results move at round-off against a libm build (docs/performance.md,
// "Session 10").
//
// The algorithm is fdlibm's (musl's src/math/__sin.c, __cos.c, __rem_pio2.c):
//  - reduction x = n (pi/2) + y, |y| <= pi/4, in Cody and Waite's three steps with pi/2 in three 33-bit
//    pieces (the third only when the first two cancel more than 49 bits), y = y0 + y1 in double-double;
//  - sin and cos of y by the degree-13 and -14 minimax polynomials of fdlibm's __kernel_sin and
//    __kernel_cos, whose coefficients these are;
//  - |x| beyond 2^19 pi/2 (where n (pi/2) is no longer exact in the pieces) and non-finite x go to libm.
// Odd and even to the bit: sin(-x) = -sin(x), cos(-x) = cos(x) (Kanayama::compute relies on it).
//
// Derived from fdlibm: Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved. Developed at
// SunPro, a Sun Microsystems, Inc. business. Permission to use, copy, modify, and distribute this
// software is freely granted, provided that this notice is preserved.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include <Eigen/Core>

namespace sowing_robot {
namespace core {
namespace trig_detail {

constexpr double kInvPio2 = 6.36619772367581382433e-01;  // 53 bits of 2/pi
constexpr double kPio2_1 = 1.57079632673412561417e+00;   // first 33 bits of pi/2
constexpr double kPio2_2 = 6.07710050630396597660e-11;   // second 33 bits
constexpr double kPio2_2t = 2.02226624879595063154e-21;  // pi/2 - (pio2_1 + pio2_2)
constexpr double kPio2_3 = 2.02226624871116645580e-21;   // third 33 bits
constexpr double kPio2_3t = 8.47842766036889956997e-32;  // pi/2 - (pio2_1 + pio2_2 + pio2_3)
constexpr double kToInt = 6755399441055744.0;            // 1.5 * 2^52: x + kToInt - kToInt rounds x to an integer
constexpr double kMedium = 823549.6;                     // ~2^19 pi/2: fdlibm's bound of this reduction
constexpr double kTiny = 0x1p-27;                        // below: sin x = x and cos x = 1 to the bit

constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03, S3 = -1.98412698298579493134e-04,
                 S4 = 2.75573137070700676789e-06, S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03, C3 = 2.48015872894767294178e-05,
                 C4 = -2.75573143513906633035e-07, C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;

/// sin(y0 + y1) for |y0 + y1| <= pi/4 (fdlibm's __kernel_sin with the tail).
template <typename N>
inline N kernelSin(N y0, N y1) {
  const N z = y0 * y0, w = z * z, r = N(S2) + z * (N(S3) + z * N(S4)) + z * w * (N(S5) + z * N(S6)), v = z * y0;
  return y0 - ((z * (N(0.5) * y1 - v * r) - y1) - v * N(S1));
}

/// cos(y0 + y1) for |y0 + y1| <= pi/4 (fdlibm's __kernel_cos as musl writes it).
template <typename N>
inline N kernelCos(N y0, N y1) {
  const N z = y0 * y0, w = z * z, r = z * (N(C1) + z * (N(C2) + z * N(C3))) + w * w * (N(C4) + z * (N(C5) + z * N(C6)));
  const N hz = N(0.5) * z, one_minus = N(1.0) - hz;
  return one_minus + (((N(1.0) - one_minus) - hz) + (z * r - y0 * y1));
}

inline int biasedExponent(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return static_cast<int>((bits >> 52) & 0x7ff);
}

/// x = n pi/2 + y0 + y1 for tiny < |x| < kMedium; returns n (its low two bits are the quadrant).
inline int reduce(double x, double& y0, double& y1) {
  const double fn = (x * kInvPio2 + kToInt) - kToInt;
  // Rounds 1 and 2 (118 bits of pi/2): x - fn pio2_1 is exact, as fn < 2^20 and pio2_1 has 33 bits.
  const double t = x - fn * kPio2_1;
  double w = fn * kPio2_2;
  double r = t - w;
  w = fn * kPio2_2t - ((t - r) - w);
  y0 = r - w;
  if (biasedExponent(x) - biasedExponent(y0) > 49) {  // x within ~2^-49 |x| of a multiple of pi/2
    const double t2 = r;
    w = fn * kPio2_3;
    r = t2 - w;
    w = fn * kPio2_3t - ((t2 - r) - w);
    y0 = r - w;
  }
  y1 = (r - y0) - w;
  return static_cast<int>(fn);
}

}  // namespace trig_detail

/// sin and cos of x [rad], within 1 ulp.
inline void sinCos(double x, double& sin_x, double& cos_x) {
  using namespace trig_detail;
  const double ax = std::fabs(x);
  if (ax < kTiny) {
    sin_x = x;  // keeps -0.0
    cos_x = 1.0;
    return;
  }
  if (!(ax < kMedium)) {  // huge or non-finite (NaN fails every comparison)
    sin_x = std::sin(x);
    cos_x = std::cos(x);
    return;
  }
  double y0, y1;
  const int n = reduce(x, y0, y1);
  const double s = kernelSin(y0, y1), c = kernelCos(y0, y1);
  switch (n & 3) {
    case 0:
      sin_x = s;
      cos_x = c;
      break;
    case 1:
      sin_x = c;
      cos_x = -s;
      break;
    case 2:
      sin_x = -s;
      cos_x = -c;
      break;
    default:
      sin_x = -c;
      cos_x = s;
      break;
  }
}

/// (cos h, sin h), the unit vector of heading h, from one sinCos.
inline Eigen::Vector2d unitVector(double heading) {
  double s, c;
  sinCos(heading, s, c);
  return {c, s};
}

/// sin x, the same bits as sinCos's.
inline double sinOf(double x) {
  using namespace trig_detail;
  const double ax = std::fabs(x);
  if (ax < kTiny) return x;
  if (!(ax < kMedium)) return std::sin(x);
  double y0, y1;
  const int n = reduce(x, y0, y1);
  const double v = (n & 1) ? kernelCos(y0, y1) : kernelSin(y0, y1);
  return (n & 2) ? -v : v;
}

/// cos x, the same bits as sinCos's.
inline double cosOf(double x) {
  using namespace trig_detail;
  const double ax = std::fabs(x);
  if (ax < kTiny) return 1.0;
  if (!(ax < kMedium)) return std::cos(x);
  double y0, y1;
  const int n = reduce(x, y0, y1);
  const double v = (n & 1) ? kernelSin(y0, y1) : kernelCos(y0, y1);
  return ((n + 1) & 2) ? -v : v;
}

}  // namespace core
}  // namespace sowing_robot
