// A curved sowing row for the benchmark's sine_rows scenario: x_d = x0 + u t, y_d = y0 + A sin(2 pi (x_d - x0) / L).
// The field reference (field.h) drives straight rows only; this reference gives the controllers a row whose
// curvature changes sign every half wavelength (peak A (2 pi / L)^2), with the exact heading, speed, yaw rate and
// their derivatives, so the feedforward terms the controllers use are right.
#pragma once

#include <cmath>
#include <memory>
#include <string>

#include "sowing_robot/core/common/reference.h"

namespace sowing_robot {
namespace core {

struct SineRowParams {
  double x0 = 0.0;           ///< row start x [m]
  double y0 = 3.0;           ///< row centre line y [m]
  double speed_x = 1.0;      ///< u: along-x speed [m/s] (the path speed is u sqrt(1 + (A k cos)^2))
  double amplitude = 0.5;    ///< A [m]
  double wavelength = 10.0;  ///< L [m]
  /// "" or one line naming the bad value.
  std::string validate() const {
    if (!(std::isfinite(x0) && std::isfinite(y0))) return "sine: x0 and y0 must be finite";
    if (!(speed_x > 0.0 && std::isfinite(speed_x))) return "sine: speed_x must be > 0";
    if (!(amplitude >= 0.0 && std::isfinite(amplitude))) return "sine: amplitude must be >= 0";
    if (!(wavelength > 0.0 && std::isfinite(wavelength))) return "sine: wavelength must be > 0";
    return "";
  }
};

class SineReference : public ReferenceSource {
 public:
  explicit SineReference(const SineRowParams& p = {}) : p_(p) {}
  std::unique_ptr<ReferenceSource> clone() const override {
    auto c = std::make_unique<SineReference>(*this);
    c->reset();
    return c;
  }

 protected:
  void restart() override {}
  Reference evaluate(double t) override {
    const double k = 2.0 * M_PI / p_.wavelength, u = p_.speed_x, a = p_.amplitude;
    const double phi = k * u * t;
    double s, c;
    s = std::sin(phi);
    c = std::cos(phi);
    // Derivatives of (x, y) in t: x' = u, x'' = 0; y' = u A k cos, y'' = -u^2 A k^2 sin, y''' = -u^3 A k^3 cos.
    const double yd = u * a * k * c, ydd = -u * u * a * k * k * s, yddd = -u * u * u * a * k * k * k * c;
    const double v2 = u * u + yd * yd, v = std::sqrt(v2);
    Reference r;
    r.pose = {p_.x0 + u * t, p_.y0 + a * s, std::atan2(yd, u)};
    r.v = v;
    r.v_dot = yd * ydd / v;
    r.omega = u * ydd / v2;                                            // (x' y'' - y' x'') / v^2
    r.omega_dot = u * (yddd * v2 - 2.0 * ydd * yd * ydd) / (v2 * v2);  // d/dt (u y'' / v^2), (v^2)' = 2 y' y''
    return r;
  }

 private:
  SineRowParams p_;
};

}  // namespace core
}  // namespace sowing_robot
