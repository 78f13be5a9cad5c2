#include "sowing_robot/core/model/plant.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/common/validation.h"

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

void Plant::setMotor(const MotorParams& motor) {
  const std::string error = motor.validate();
  if (!error.empty()) throw std::invalid_argument(error);
  motor_[0] = motor_[1] = WheelMotor(motor);
}

void Plant::reset(const State& initial, double t) {
  if (!initial.allFinite() || !std::isfinite(t)) throw std::invalid_argument("plant reset: non-finite state or time");
  state_ = initial;
  time_ = t;
  motor_[0].reset();
  motor_[1].reset();
  applied_[0] = applied_[1] = 0.0;
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
  double s, c;
  s = std::sin(angle);
  c = std::cos(angle);
  right = amplitude * s;
  left = amplitude * c;
}

}  // namespace

void Plant::sinusoidalDisturbance(double t, double& right, double& left) const {
  sinusoid(disturbance_, t, right, left);
}

State Plant::derivative(const State& s, double applied_right, double applied_left) const {
  double c, sn;
  sn = std::sin(s[THETA]);
  c = std::cos(s[THETA]);
  return derivativeWithHeading(s, c, sn, applied_right, applied_left);
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
  double c, s;
  s = std::sin(state_[THETA]);
  c = std::cos(state_[THETA]);
  return stepWithHeading(tau_right, tau_left, dt, c, s);
}

namespace {

// The rates of one RK4 stage (eq 3.13, 3.54) on plain numbers: the same operations, in the same order, as
// derivativeWithHeading() on the Eigen state, without the temporaries. Wheel angles never enter a
// derivative, so the stage states only carry x, y, theta, v, omega.
struct Rates {
  double x, y, theta, v, omega, phi_r, phi_l;
};

struct PlantCoefficients {
  double mcd, m0, i0, R, L;
};

inline Rates stageRates(const PlantCoefficients& p, double v, double w, double cos_heading, double sin_heading,
                        double applied_right, double applied_left) {
  const double u1 = applied_right + applied_left, u2 = applied_right - applied_left;
  Rates k;
  k.x = v * cos_heading;
  k.y = v * sin_heading;
  k.theta = w;
  k.v = (p.mcd * w * w + u1 / p.R) / p.m0;
  k.omega = (-p.mcd * w * v + p.L * u2 / p.R) / p.i0;
  k.phi_r = (v + p.L * w) / p.R;
  k.phi_l = (v - p.L * w) / p.R;
  return k;
}

// The disturbance's time at RK4 stage `stage` (0..3) of the step from t: t, t + h/2 twice, t + h.
inline double stageTime(double t, double h, int stage) { return stage == 0 ? t : (stage == 3 ? t + h : t + 0.5 * h); }

// One RK4 step of (x, y, theta, v, omega, phi_r, phi_l): stage(k, v, omega, heading increment) gives the
// rates of stage k. The increments, sixth (k1 + 2 k2 + 2 k3 + k4), go into *increment.
template <typename Stage>
inline void rk4Increment(double v0, double w0, double h, const Stage& stage, Rates& increment) {
  const double half = 0.5 * h, whole = h, two = 2.0;
  const Rates k1 = stage(0, v0, w0, 0.0);
  const Rates k2 = stage(1, v0 + half * k1.v, w0 + half * k1.omega, half * k1.theta);
  const Rates k3 = stage(2, v0 + half * k2.v, w0 + half * k2.omega, half * k2.theta);
  const Rates k4 = stage(3, v0 + whole * k3.v, w0 + whole * k3.omega, whole * k3.theta);
  const double sixth = h / 6.0;
  auto combine = [&](double a, double b, double c, double d) { return sixth * (a + two * b + two * c + d); };
  increment.x = combine(k1.x, k2.x, k3.x, k4.x);
  increment.y = combine(k1.y, k2.y, k3.y, k4.y);
  increment.theta = combine(k1.theta, k2.theta, k3.theta, k4.theta);
  increment.v = combine(k1.v, k2.v, k3.v, k4.v);
  increment.omega = combine(k1.omega, k2.omega, k3.omega, k4.omega);
  increment.phi_r = combine(k1.phi_r, k2.phi_r, k3.phi_r, k4.phi_r);
  increment.phi_l = combine(k1.phi_l, k2.phi_l, k3.phi_l, k4.phi_l);
}

}  // namespace

inline void Plant::drawNoise(double& right, double& left) {
  right = left = 0.0;
  if (disturbance_.noise_std > 0.0) {
    right = disturbance_.noise_std * noise_.next();
    left = disturbance_.noise_std * noise_.next();
  }
}

inline void Plant::addIncrement(double x, double y, double theta, double v, double omega, double phi_r, double phi_l,
                                double dt) {
  state_[X] += x;
  state_[Y] += y;
  state_[THETA] += theta;
  state_[V] += v;
  state_[OMEGA] += omega;
  state_[PHI_R] += phi_r;
  state_[PHI_L] += phi_l;
  time_ += dt;
}

// cos0, sin0: cos and sin of state_[THETA].
inline bool Plant::stepWithHeading(double tau_right, double tau_left, double dt, double cos0, double sin0) {
  if (!allFinite(tau_right, tau_left, dt) || !(dt > 0.0)) return false;
  double noise_r, noise_l;
  drawNoise(noise_r, noise_l);
  if (motor_[0].params().enabled) {  // each wheel's motor at the wheel's spin rate (rolling: (v ± L w) / R)
    const double v = state_[V], w = state_[OMEGA], R = nominal_.R, L = nominal_.L;
    tau_right = motor_[0].apply(tau_right, (v + L * w) / R, dt);
    tau_left = motor_[1].apply(tau_left, (v - L * w) / R, dt);
  }
  applied_[0] = tau_right;
  applied_[1] = tau_left;
  // The sinusoid is evaluated at each RK4 stage time; command and noise are held over the step.
  // Stages 2 and 3 share t + h/2, and stage 4's t + h is the next step's stage 1 (disturbanceAt).
  // Stage 1 is at the step's heading (cos0, sin0); the later stages take the cos/sin of their own heading.
  const double t = time_, h = dt, theta0 = state_[THETA];
  const double applied_r0 = tau_right + noise_r, applied_l0 = tau_left + noise_l;
  const PlantCoefficients p{mcd_, m0_, i0_, nominal_.R, nominal_.L};
  auto stage = [&](int k, double v, double w, double heading_increment) {
    double dr, dl, c = cos0, sn = sin0;
    disturbanceAt(stageTime(t, h, k), dr, dl);
    if (k != 0) {
      const double heading = theta0 + heading_increment;
      sn = std::sin(heading);
      c = std::cos(heading);
    }
    return stageRates(p, v, w, c, sn, applied_r0 + dr, applied_l0 + dl);
  };
  Rates d;
  rk4Increment(state_[V], state_[OMEGA], h, stage, d);
  addIncrement(d.x, d.y, d.theta, d.v, d.omega, d.phi_r, d.phi_l, dt);
  return true;
}

Eigen::Vector2d Plant::centreOfMass() const {
  return Eigen::Vector2d(state_[X], state_[Y]) + nominal_.d * unitVector(state_[THETA]);
}

}  // namespace core
}  // namespace sowing_robot
