// The half-cosine speed ramp both timed paths are made of (field.h's FieldPath, path_plan.h's PathPlan): the
// speed goes from v0 to v1 as v0 + (v1 - v0)(1 - cos(pi tau / T))/2, so the acceleration is continuous and its
// peak is pi |v1 - v0| / (2 T). A phase with v0 == v1 is a cruise.
#pragma once

#include <cmath>

namespace sowing_robot {
namespace core {

/// Distance a ramp between speeds v0 and v1 needs at peak acceleration a [m].
inline double rampDistance(double v0, double v1, double a) { return M_PI * std::fabs(v1 * v1 - v0 * v0) / (4.0 * a); }

/// Duration of a phase covering `distance` from v0 to v1: a ramp at peak acceleration a, or a cruise [s].
inline double phaseDuration(double distance, double v0, double v1, double a) {
  return v0 == v1 ? distance / v0 : M_PI * std::fabs(v1 - v0) / (2.0 * a);
}

/// Arc length and its derivatives tau seconds into a phase starting at s0 (duration T).
struct RampState {
  double s = 0.0, sd = 0.0, sdd = 0.0, sddd = 0.0;
};
inline RampState rampState(double s0, double v0, double v1, double duration, double tau) {
  RampState r;
  if (v0 == v1) {
    r.s = s0 + v0 * tau;
    r.sd = v0;
    return r;
  }
  const double dv = v1 - v0, w = M_PI / duration;
  const double sn = std::sin(w * tau), c = std::cos(w * tau);
  r.s = s0 + v0 * tau + 0.5 * dv * (tau - sn / w);
  r.sd = v0 + 0.5 * dv * (1.0 - c);
  r.sdd = 0.5 * dv * w * sn;
  r.sddd = 0.5 * dv * w * w * c;
  return r;
}

}  // namespace core
}  // namespace sowing_robot
