#include "sowing_robot/core/plant.h"

#include <cmath>

#include "sowing_robot/core/validation.h"

namespace sowing_robot {
namespace core {

std::string PlantDisturbance::validate() const {
  return firstError({checkNonNegative("disturbance.amplitude", amplitude, "N·m"),
                     checkNonNegative("disturbance.frequency", frequency, "rad/s"),
                     checkNonNegative("noise.std", noise_std, "N·m"),
                     checkRange("mismatch.mass_scale", mass_scale, 0.1, 10.0),
                     checkRange("mismatch.inertia_scale", inertia_scale, 0.1, 10.0)});
}

Plant::Plant(const RobotParams& nominal, const PlantDisturbance& disturbance)
    : nominal_(nominal),
      disturbance_(disturbance),
      m0_(nominal.m0() * disturbance.mass_scale),
      i0_(nominal.I0() * disturbance.inertia_scale),
      mcd_(nominal.mc * nominal.d * disturbance.mass_scale),
      rng_(disturbance.seed) {}

void Plant::reset(const State& initial, double t) {
  state_ = initial;
  time_ = t;
  rng_.seed(disturbance_.seed);
  noise_.reset();
}

void Plant::sinusoidalDisturbance(double t, double& right, double& left) const {
  if (!disturbance_.sinusoidal) {
    right = left = 0.0;
    return;
  }
  right = disturbance_.amplitude * std::sin(disturbance_.frequency * t);
  left = disturbance_.amplitude * std::cos(disturbance_.frequency * t);
}

State Plant::derivative(const State& s, double applied_right, double applied_left) const {
  const double v = s[V], w = s[OMEGA], th = s[THETA];
  const double u1 = applied_right + applied_left, u2 = applied_right - applied_left;
  State ds;
  // eq 3.13: unicycle kinematics of the axle midpoint
  ds[X] = v * std::cos(th);
  ds[Y] = v * std::sin(th);
  ds[THETA] = w;
  // eq 3.54: m0 v' - mc d w^2 = u1 / R ;  I0 w' + mc d w v = L u2 / R
  ds[V] = (mcd_ * w * w + u1 / nominal_.R) / m0_;
  ds[OMEGA] = (-mcd_ * w * v + nominal_.L * u2 / nominal_.R) / i0_;
  // rolling without slip: wheel rates from body velocities
  ds[PHI_R] = (v + nominal_.L * w) / nominal_.R;
  ds[PHI_L] = (v - nominal_.L * w) / nominal_.R;
  return ds;
}

void Plant::step(double tau_right, double tau_left, double dt) {
  double noise_r = 0.0, noise_l = 0.0;
  if (disturbance_.noise_std > 0.0) {
    noise_r = disturbance_.noise_std * noise_(rng_);
    noise_l = disturbance_.noise_std * noise_(rng_);
  }
  // The sinusoid is evaluated at each RK4 stage time; command and noise are held over the step.
  auto f = [&](const State& s, double t) {
    double dr, dl;
    sinusoidalDisturbance(t, dr, dl);
    return derivative(s, tau_right + noise_r + dr, tau_left + noise_l + dl);
  };
  const double t = time_, h = dt;
  const State k1 = f(state_, t);
  const State k2 = f(state_ + 0.5 * h * k1, t + 0.5 * h);
  const State k3 = f(state_ + 0.5 * h * k2, t + 0.5 * h);
  const State k4 = f(state_ + h * k3, t + h);
  state_ += (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  time_ += dt;
}

Eigen::Vector2d Plant::centreOfMass() const {
  return {state_[X] + nominal_.d * std::cos(state_[THETA]), state_[Y] + nominal_.d * std::sin(state_[THETA])};
}

}  // namespace core
}  // namespace sowing_robot
