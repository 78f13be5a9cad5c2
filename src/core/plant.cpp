#include "sowing_robot/core/plant.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "sowing_robot/core/rotation.h"
#include "sowing_robot/core/types.h"
#include "sowing_robot/core/validation.h"

namespace sowing_robot {
namespace core {

const ParamTable<PlantDisturbance>& disturbanceTable() {
  using D = PlantDisturbance;
  static const ParamTable<D> table({
      flag("disturbance/sinusoidal", &D::sinusoidal, false,
           "add the wheel-torque disturbance of Fig 5.9: td_R = A sin(w t), td_L = A cos(w t)"),
      number("disturbance/amplitude", &D::amplitude, 2.75, Limits::nonNegative(), "N·m", "A"),
      number("disturbance/frequency", &D::frequency, 3.0, Limits::nonNegative(), "rad/s", "w"),
      number("noise/std", &D::noise_std, 0.0, Limits::nonNegative(), "N·m",
             "Gaussian wheel-torque noise, held per step; 0 = off"),
      integer("noise/seed", &D::seed, 1, Limits::nonNegative(), "", "noise generator seed"),
      number("mismatch/mass_scale", &D::mass_scale, 1.0, Limits::closed(0.1, 10.0), "",
             "the plant's true m0 and mc·d = this × the URDF's (the controllers' model)"),
      number("mismatch/inertia_scale", &D::inertia_scale, 1.0, Limits::closed(0.1, 10.0), "",
             "the plant's true I0 = this × the URDF's"),
  });
  return table;
}

PlantDisturbance::PlantDisturbance() { disturbanceTable().applyDefaults(*this); }

std::string PlantDisturbance::validate() const { return disturbanceTable().checkRanges(*this); }

Plant::Plant(const RobotParams& nominal, const PlantDisturbance& disturbance)
    : nominal_(nominal),
      disturbance_(disturbance),
      m0_(nominal.m0() * disturbance.mass_scale),
      i0_(nominal.I0() * disturbance.inertia_scale),
      mcd_(nominal.mc * nominal.d * disturbance.mass_scale),
      noise_(disturbance.seed) {
  const std::string error = firstError({nominal.validate(), disturbance.validate()});
  if (!error.empty()) throw std::invalid_argument(error);
}

void Plant::reset(const State& initial, double t) {
  if (!initial.allFinite() || !std::isfinite(t)) throw std::invalid_argument("plant reset: non-finite state or time");
  state_ = initial;
  time_ = t;
  noise_.seed(disturbance_.seed);
  cached_disturbance_time_ = std::numeric_limits<double>::quiet_NaN();
}

namespace {

// The sinusoid of Fig 5.9. One angle held in a local: writing through right could alias the
// parameters, which would make the compiler recompute the product and miss fusing sin and cos into one
// sincos call. A file-local function, so that step() gets it inlined (a member of the shared library
// is called through its PLT: semantic interposition).
inline void sinusoid(const PlantDisturbance& d, double t, double& right, double& left) {
  if (!d.sinusoidal) {
    right = left = 0.0;
    return;
  }
  const double angle = d.frequency * t, amplitude = d.amplitude;
  right = amplitude * std::sin(angle);
  left = amplitude * std::cos(angle);
}

}  // namespace

void Plant::sinusoidalDisturbance(double t, double& right, double& left) const {
  sinusoid(disturbance_, t, right, left);
}

State Plant::derivative(const State& s, double applied_right, double applied_left) const {
  return derivativeWithHeading(s, std::cos(s[THETA]), std::sin(s[THETA]), applied_right, applied_left);
}

// derivative() with cos/sin of the heading supplied (step() writes the same arithmetic out on scalars).
inline State Plant::derivativeWithHeading(const State& s, double cos_th, double sin_th, double applied_right,
                                          double applied_left) const {
  const double v = s[V], w = s[OMEGA];
  const double u1 = applied_right + applied_left, u2 = applied_right - applied_left;
  State ds;
  // eq 3.13: unicycle kinematics of the axle midpoint
  ds[X] = v * cos_th;
  ds[Y] = v * sin_th;
  ds[THETA] = w;
  // eq 3.54: m0 v' - mc d w^2 = u1 / R ;  I0 w' + mc d w v = L u2 / R
  ds[V] = (mcd_ * w * w + u1 / nominal_.R) / m0_;
  ds[OMEGA] = (-mcd_ * w * v + nominal_.L * u2 / nominal_.R) / i0_;
  // rolling without slip: wheel rates from body velocities
  ds[PHI_R] = (v + nominal_.L * w) / nominal_.R;
  ds[PHI_L] = (v - nominal_.L * w) / nominal_.R;
  return ds;
}

inline void Plant::disturbanceAt(double t, double& right, double& left) {
  // RK4 asks for three times per step (t, t + h/2 twice, t + h) and the next step starts where this one
  // ended: remembering the last time evaluated halves the sin/cos calls, with bit-identical values.
  if (t != cached_disturbance_time_) {
    sinusoid(disturbance_, t, cached_disturbance_right_, cached_disturbance_left_);
    cached_disturbance_time_ = t;
  }
  right = cached_disturbance_right_;
  left = cached_disturbance_left_;
}

bool Plant::step(double tau_right, double tau_left, double dt) {
  return stepWithHeading(tau_right, tau_left, dt, std::cos(state_[THETA]), std::sin(state_[THETA]));
}

bool Plant::step(double tau_right, double tau_left, double dt, double theta, double cos_theta, double sin_theta) {
  // Bit pattern, not ==: -0.0 == 0.0, but their sines differ in sign.
  if (std::memcmp(&theta, &state_[THETA], sizeof theta) == 0)
    return stepWithHeading(tau_right, tau_left, dt, cos_theta, sin_theta);
  return step(tau_right, tau_left, dt);
}

// cos0, sin0: cos and sin of state_[THETA].
inline bool Plant::stepWithHeading(double tau_right, double tau_left, double dt, double cos0, double sin0) {
  if (!allFinite(tau_right, tau_left, dt) || !(dt > 0.0)) return false;
  double noise_r = 0.0, noise_l = 0.0;
  if (disturbance_.noise_std > 0.0) {
    noise_r = disturbance_.noise_std * noise_.next();
    noise_l = disturbance_.noise_std * noise_.next();
  }
  // The sinusoid is evaluated at each RK4 stage time; command and noise are held over the step.
  // Stages 2 and 3 share t + h/2, and stage 4's t + h is the next step's stage 1.
  // The heading's cos/sin come from one sincos at the start of the step, turned by each stage's small
  // heading increment (rotateHeading), instead of a sincos per stage.
  const double t = time_, h = dt;
  // Each stage's derivative (eq 3.13, 3.54) on plain scalars: the same operations, in the same order, as
  // derivativeWithHeading() on the Eigen state (the RK4 below is Eigen's element-wise evaluation of
  // s + (h/2) k, written out), without the temporaries. Wheel angles never enter a derivative, so the
  // stage states only carry x, y, theta, v, omega.
  const double R = nominal_.R, L = nominal_.L;
  const double applied_r0 = tau_right + noise_r, applied_l0 = tau_left + noise_l;
  struct Rates {
    double x, y, theta, v, omega, phi_r, phi_l;
  };
  auto f = [&](double v, double w, double ts, double heading_increment) {
    double dr, dl, c, sn;
    disturbanceAt(ts, dr, dl);
    rotateHeading(cos0, sin0, heading_increment, c, sn);
    const double applied_right = applied_r0 + dr, applied_left = applied_l0 + dl;
    const double u1 = applied_right + applied_left, u2 = applied_right - applied_left;
    Rates k;
    k.x = v * c;
    k.y = v * sn;
    k.theta = w;
    k.v = (mcd_ * w * w + u1 / R) / m0_;
    k.omega = (-mcd_ * w * v + L * u2 / R) / i0_;
    k.phi_r = (v + L * w) / R;
    k.phi_l = (v - L * w) / R;
    return k;
  };
  const double v0 = state_[V], w0 = state_[OMEGA];
  const double half = 0.5 * h;
  const Rates k1 = f(v0, w0, t, 0.0);
  const Rates k2 = f(v0 + half * k1.v, w0 + half * k1.omega, t + 0.5 * h, 0.5 * h * k1.theta);
  const Rates k3 = f(v0 + half * k2.v, w0 + half * k2.omega, t + 0.5 * h, 0.5 * h * k2.theta);
  const Rates k4 = f(v0 + h * k3.v, w0 + h * k3.omega, t + h, h * k3.theta);
  const double sixth = h / 6.0;
  auto combine = [sixth](double a, double b, double c, double d) { return sixth * (a + 2.0 * b + 2.0 * c + d); };
  state_[X] += combine(k1.x, k2.x, k3.x, k4.x);
  state_[Y] += combine(k1.y, k2.y, k3.y, k4.y);
  state_[THETA] += combine(k1.theta, k2.theta, k3.theta, k4.theta);
  state_[V] += combine(k1.v, k2.v, k3.v, k4.v);
  state_[OMEGA] += combine(k1.omega, k2.omega, k3.omega, k4.omega);
  state_[PHI_R] += combine(k1.phi_r, k2.phi_r, k3.phi_r, k4.phi_r);
  state_[PHI_L] += combine(k1.phi_l, k2.phi_l, k3.phi_l, k4.phi_l);
  time_ += dt;
  return true;
}

Eigen::Vector2d Plant::centreOfMass() const {
  return {state_[X] + nominal_.d * std::cos(state_[THETA]), state_[Y] + nominal_.d * std::sin(state_[THETA])};
}

}  // namespace core
}  // namespace sowing_robot
