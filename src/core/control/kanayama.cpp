#include "sowing_robot/core/control/kanayama.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

const ParamTable<KanayamaGains>& kanayamaTable() {
  using G = KanayamaGains;
  static const ParamTable<G> table({
      tunable(number("kx", &G::kx, 1.0, Limits::positive(), "1/s", "Kanayama gain on the along-track error xe")),
      tunable(number("ky", &G::ky, 1.5, Limits::positive(), "1/m^2", "Kanayama gain on the cross-track error ye")),
      tunable(number("ktheta", &G::ktheta, 2.2, Limits::positive(), "1/m", "Kanayama gain on sin(theta_e)")),
  });
  return table;
}

KanayamaGains::KanayamaGains() { kanayamaTable().applyDefaults(*this); }

std::string KanayamaGains::validate() const { return kanayamaTable().checkRanges(*this); }

Kanayama::Kanayama(const KanayamaGains& gains) { setGains(gains); }

void Kanayama::setGains(const KanayamaGains& g) {
  const std::string error = g.validate();
  if (!error.empty()) throw std::invalid_argument(error);
  gains_ = g;
}

PostureError Kanayama::postureError(const Pose2D& r, const Pose2D& a) {
  // eq 4.1
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  const double dx = r.x - a.x, dy = r.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, wrapAngle(r.theta - a.theta)};
}

VelocityCommand Kanayama::compute(const Reference& ref, const Pose2D& actual, double v, double omega) const {
  if (ref.stop) return holdCommand();
  if (!allFinite(ref.pose.x, ref.pose.y, ref.pose.theta, ref.v, ref.omega, ref.v_dot, ref.omega_dot, actual.x, actual.y,
                 actual.theta, v, omega))
    return VelocityCommand{};
  const PostureError e = postureError(ref.pose, actual);
  const double c = std::cos(e.thetae), s = std::sin(e.thetae);
  VelocityCommand out;
  out.v = ref.v * c + gains_.kx * e.xe;
  out.omega = ref.omega + ref.v * (gains_.ky * e.ye + gains_.ktheta * s);
  // Error dynamics (eq 4.15) with the robot's measured velocities.
  const double xe_dot = omega * e.ye - v + ref.v * c;
  const double ye_dot = -omega * e.xe + ref.v * s;
  const double thetae_dot = ref.omega - omega;
  out.v_dot = ref.v_dot * c - ref.v * s * thetae_dot + gains_.kx * xe_dot;
  out.omega_dot = ref.omega_dot + ref.v_dot * (gains_.ky * e.ye + gains_.ktheta * s) +
                  ref.v * (gains_.ky * ye_dot + gains_.ktheta * c * thetae_dot);
  return out;
}

double Kanayama::lyapunov(const PostureError& e) const {
  return 0.5 * (e.xe * e.xe + e.ye * e.ye) + (1.0 - std::cos(e.thetae)) / gains_.ky;
}

}  // namespace core
}  // namespace sowing_robot
