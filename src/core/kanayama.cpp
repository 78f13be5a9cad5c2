#include "sowing_robot/core/kanayama.h"

#include <cmath>
#include <stdexcept>

#include "sowing_robot/core/validation.h"

namespace sowing_robot {
namespace core {

std::string KanayamaGains::validate() const {
  return firstError({checkPositive("kx", kx, "1/s"), checkPositive("ky", ky, "1/m^2"),
                     checkPositive("ktheta", ktheta, "1/m")});
}

Kanayama::Kanayama(const KanayamaGains& gains) { setGains(gains); }

void Kanayama::setGains(const KanayamaGains& g) {
  const std::string error = g.validate();
  if (!error.empty()) throw std::invalid_argument(error);
  gains_ = g;
}

PostureError Kanayama::postureError(const Pose2D& r, const Pose2D& a) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  const double dx = r.x - a.x, dy = r.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, wrapAngle(r.theta - a.theta)};
}

VelocityCommand Kanayama::compute(const Reference& ref, const Pose2D& actual, double v, double omega) const {
  if (!allFinite(ref.pose.x, ref.pose.y, ref.pose.theta, ref.v, ref.omega, ref.v_dot, ref.omega_dot, actual.x,
                 actual.y, actual.theta, v, omega))
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
