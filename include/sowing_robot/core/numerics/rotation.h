// cos and sin of (a + delta) from cos(a) and sin(a): turning a heading by a small increment without a
// sincos per step. Shared by the no-slip Plant (RK4 stages) and the TractionPlant (sub-steps).
#pragma once

#include <cmath>

namespace sowing_robot {
namespace core {

// cos and sin of (theta + delta) from cos0 = cos(theta), sin0 = sin(theta) by the angle-sum identity and
// the Taylor series of cos(delta), sin(delta), for |delta| <= 0.05 (rotateHeading's case).
inline void rotateBySeries(double cos0, double sin0, double delta, double& cos_out, double& sin_out) {
  const double d2 = delta * delta;
  const double one = 1.0, half = 0.5;
  const double k6 = 1.0 / 6.0, k20 = 1.0 / 20.0, k42 = 1.0 / 42.0;    // 3!, 5!/3!, 7!/5!
  const double k12 = 1.0 / 12.0, k30 = 1.0 / 30.0, k56 = 1.0 / 56.0;  // 4!/2!, 6!/4!, 8!/6!
  const double sd = delta * (one - d2 * k6 * (one - d2 * k20 * (one - d2 * k42)));
  const double cd = one - half * d2 * (one - d2 * k12 * (one - d2 * k30 * (one - d2 * k56)));
  cos_out = cos0 * cd - sin0 * sd;
  sin_out = sin0 * cd + cos0 * sd;
}

// cos and sin of (theta + delta) from cos0 = cos(theta), sin0 = sin(theta).
// RK4's heading increments are small (delta = h w / 2 or h w: 1e-3 rad at 1 kHz and 2 rad/s), where the
// Taylor series are exact to double rounding (first dropped terms delta^9/9! and delta^10/10!, about
// 1e-16 of the kept ones at |delta| = 0.05); larger increments fall back to the library.
inline void rotateHeading(double cos0, double sin0, double delta, double& cos_out, double& sin_out) {
  if (std::fabs(delta) <= 0.05) {
    rotateBySeries(cos0, sin0, delta, cos_out, sin_out);
    return;
  }
  double sd, cd;
  sd = std::sin(delta);
  cd = std::cos(delta);
  cos_out = cos0 * cd - sin0 * sd;
  sin_out = sin0 * cd + cos0 * sd;
}

}  // namespace core
}  // namespace sowing_robot
