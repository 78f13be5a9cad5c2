#include "sowing_robot/core/control/pure_pursuit.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/control/kanayama.h"

namespace sowing_robot {
namespace core {

const ParamTable<PurePursuitParams>& purePursuitTable() {
  using P = PurePursuitParams;
  static const ParamTable<P> table({
      tunable(number("lookahead_dist", &P::lookahead_dist, 0.6, Limits::positive(), "m",
                     "lookahead distance L (nav2 lookahead_dist), within [min, max]_lookahead_dist")),
      number("min_lookahead_dist", &P::min_lookahead_dist, 0.3, Limits::positive(), "m", "smallest lookahead"),
      number("max_lookahead_dist", &P::max_lookahead_dist, 0.9, Limits::positive(), "m", "largest lookahead"),
      number("lookahead_time", &P::lookahead_time, 1.5, Limits::positive(), "s",
             "velocity-scaled lookahead L = |v| lookahead_time, clamped to [min, max]"),
      flag("use_velocity_scaled_lookahead_dist", &P::use_velocity_scaled_lookahead_dist, false,
           "scale the lookahead with the measured speed (nav2's option)"),
      tunable(number("regulated_linear_scaling_min_radius", &P::min_radius, 0.9, Limits::positive(), "m",
                     "RPP: below this turning radius the speed is scaled by radius / min_radius")),
      number("regulated_linear_scaling_min_speed", &P::min_speed, 0.25, Limits::nonNegative(), "m/s",
             "RPP: the curvature heuristic never slows below this"),
      tunable(number("k_along", &P::k_along, 0.0, Limits::nonNegative(), "1/s",
                     "along-track speed feedback on the reference's xe (not in nav2; 0 = constant v_r)")),
  });
  return table;
}

PurePursuitParams::PurePursuitParams() { purePursuitTable().applyDefaults(*this); }

std::string PurePursuitParams::validate() const {
  std::string e = purePursuitTable().checkRanges(*this);
  if (!e.empty()) return e;
  e = checkOrdered("min_lookahead_dist", min_lookahead_dist, "max_lookahead_dist", max_lookahead_dist);
  if (!e.empty()) return e;
  return checkRange("lookahead_dist", lookahead_dist, min_lookahead_dist, max_lookahead_dist,
                    "m (min/max_lookahead_dist)");
}

PurePursuit::PurePursuit(const PurePursuitParams& params, bool regulated) : regulated_(regulated) { setParams(params); }

void PurePursuit::setParams(const PurePursuitParams& p) {
  const std::string error = p.validate();
  if (!error.empty()) throw std::invalid_argument(error);
  params_ = p;
}

double PurePursuit::lookahead(double v) const {
  if (!params_.use_velocity_scaled_lookahead_dist) return params_.lookahead_dist;
  return std::clamp(std::fabs(v) * params_.lookahead_time, params_.min_lookahead_dist, params_.max_lookahead_dist);
}

Pose2D PurePursuit::carrot(const Reference& ref, double L) {
  // Forward along the direction of travel (backwards when the reference reverses).
  const double s = ref.v < 0.0 ? -L : L;
  const double kappa_r = std::fabs(ref.v) > 1e-9 ? ref.omega / ref.v : 0.0;
  const double th = ref.pose.theta, dth = kappa_r * s;
  Pose2D c;
  if (std::fabs(dth) < 1e-9) {
    double sn, cs;
    sn = std::sin(th);
    cs = std::cos(th);
    c.x = ref.pose.x + s * cs;
    c.y = ref.pose.y + s * sn;
  } else {
    double s0, c0, s1, c1;
    s0 = std::sin(th);
    c0 = std::cos(th);
    s1 = std::sin(th + dth);
    c1 = std::cos(th + dth);
    c.x = ref.pose.x + (s1 - s0) / kappa_r;
    c.y = ref.pose.y - (c1 - c0) / kappa_r;
  }
  c.theta = wrapAngle(th + dth);
  return c;
}

VelocityCommand PurePursuit::compute(const Reference& ref, const Pose2D& actual, double v, double omega) const {
  if (ref.stop) return holdCommand();
  if (!allFinite(ref.pose.x, ref.pose.y, ref.pose.theta, ref.v, ref.omega, ref.v_dot, ref.omega_dot, actual.x, actual.y,
                 actual.theta, v, omega))
    return VelocityCommand{};
  const Pose2D c = carrot(ref, lookahead(v));
  // The carrot in the robot frame and its rate along the measured motion (carrot moving at v_r).
  const PostureError pc = Kanayama::postureError(c, actual);
  const double xl = pc.xe, yl = pc.ye;
  double sin_e, cos_e;
  sin_e = std::sin(pc.thetae);
  cos_e = std::cos(pc.thetae);
  const double xl_dot = ref.v * cos_e - v + omega * yl;
  const double yl_dot = ref.v * sin_e - omega * xl;
  const double d2 = xl * xl + yl * yl;
  double kappa = 0.0, kappa_dot = 0.0;
  if (d2 > 1e-12) {
    kappa = 2.0 * yl / d2;
    kappa_dot = 2.0 * yl_dot / d2 - 4.0 * yl * (xl * xl_dot + yl * yl_dot) / (d2 * d2);
  }
  // Desired speed: v_r (+ along-track feedback on the reference point's error, Kanayama's xe).
  const PostureError e = Kanayama::postureError(ref.pose, actual);
  const double xe_dot = omega * e.ye - v + ref.v * std::cos(e.thetae);
  double speed = ref.v + params_.k_along * e.xe;
  double speed_dot = ref.v_dot + params_.k_along * xe_dot;
  if (regulated_ && speed > 0.0) {
    const double abs_kappa = std::fabs(kappa);
    if (abs_kappa * params_.min_radius > 1.0) {  // radius 1/|kappa| below min_radius
      const double scaled = speed / (abs_kappa * params_.min_radius);
      if (scaled >= params_.min_speed) {
        speed_dot =
            speed_dot / (abs_kappa * params_.min_radius) - scaled * (kappa > 0.0 ? kappa_dot : -kappa_dot) / abs_kappa;
        speed = scaled;
      } else if (speed > params_.min_speed) {  // held at the floor
        speed = params_.min_speed;
        speed_dot = 0.0;
      }
    }
  }
  VelocityCommand out;
  out.v = speed;
  out.omega = speed * kappa;
  out.v_dot = speed_dot;
  out.omega_dot = speed_dot * kappa + speed * kappa_dot;
  return out;
}

}  // namespace core
}  // namespace sowing_robot
