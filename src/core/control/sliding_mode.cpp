#include "sowing_robot/core/control/sliding_mode.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

namespace {
// root^num with the sign a real odd root of a negative number keeps (even numerators are non-negative).
double powerOfRoot(double root, int num, bool negative) {
  double mag = 1.0;
  for (int i = 0; i < num; ++i) mag *= root;
  return (num % 2 == 0 || !negative) ? mag : -mag;
}
}  // namespace

double realPower(double x, int num, int den) {
  // the thesis's 5/3 and 2/3: a cube root and integer multiplications beat pow ~4x
  if (den == 3) return powerOfRoot(std::cbrt(std::fabs(x)), num, x < 0.0);
  const double mag = std::pow(std::fabs(x), static_cast<double>(num) / den);
  return (num % 2 == 0 || x >= 0.0) ? mag : -mag;
}

const ParamTable<SlidingModeParams>& slidingModeTable() {
  using P = SlidingModeParams;
  static const ParamTable<P> table = [] {
    ParamTable<P> t({
        choice("mode", &P::adaptive, true, {{"atsmc", true}, {"tsmc", false}},
               "atsmc: adaptive (eq 4.22 + projection); tsmc: fixed nominal m0, I0"),
        integer("p", &P::p, 5, Limits::atLeast(1), "", "terminal exponent numerator, odd (1 < p/q < 2)"),
        integer("q", &P::q, 3, Limits::atLeast(1), "", "terminal exponent denominator, odd"),
        tunable(number("beta_v", &P::beta_v, 1.0, Limits::positive(), "",
                       "surface gain beta, linear channel (not given in the thesis)")),
        tunable(
            number("beta_omega", &P::beta_omega, 1.0, Limits::positive(), "", "surface gain beta, angular channel")),
        tunable(number("k1", &P::k1, 1.0, Limits::positive(), "N·m·s/m", "feedback gain K1")),
        tunable(number("k2", &P::k2, 150.0, Limits::positive(), "N·m·s/rad", "feedback gain K2")),
        tunable(number("eta1", &P::eta1, 2.0, Limits::nonNegative(), "N·m", "switching gain eta1")),
        tunable(number("eta2", &P::eta2, 2.0, Limits::nonNegative(), "N·m", "switching gain eta2")),
        tunable(number("rate_m", &P::rate_m, 0.1, Limits::nonNegative(), "",
                       "adaptation rate of m0_hat (Table 5.3 gamma1; applied to S·phi, README deviation 8)")),
        tunable(number("rate_i", &P::rate_i, 0.1, Limits::nonNegative(), "", "adaptation rate of I0_hat (gamma2)")),
        choice("adaptation", &P::adaptation, Adaptation::mass_inertia,
               {{"mass_inertia", Adaptation::mass_inertia}, {"eq_4_22", Adaptation::eq_4_22}},
               "what the rates act on: mass_inertia m0_hat, I0_hat (deviation 8); eq_4_22 gamma_hat = m0_hat R, "
               "alpha_hat = I0_hat R/L (1/R, L/R x faster)"),
        number("m0_min", &P::m0_min, 17.51, Limits::positive(), "kg", "projection bound: lowest m0_hat"),
        number("m0_max", &P::m0_max, 37.51, Limits::positive(), "kg", "projection bound: highest m0_hat"),
        number("i0_min", &P::i0_min, 0.57, Limits::positive(), "kg·m^2", "projection bound: lowest I0_hat"),
        number("i0_max", &P::i0_max, 4.57, Limits::positive(), "kg·m^2", "projection bound: highest I0_hat"),
        number("m0_initial", &P::m0_initial, 0.0, Limits::nonNegative(), "kg",
               "initial m0_hat; 0 = the nominal m0 from the URDF (must lie in the bounds)"),
        number("i0_initial", &P::i0_initial, 0.0, Limits::nonNegative(), "kg·m^2",
               "initial I0_hat; 0 = the nominal I0 from the URDF"),
        number("max_torque", &P::max_torque, 100.0, Limits::positive(), "N·m",
               "per-wheel motor limit; clipping is reported"),
    });
    return t.nest("", &P::switching, switchingTable());
  }();
  return table;
}

SlidingModeParams::SlidingModeParams() { slidingModeTable().applyDefaults(*this); }

std::string SlidingModeParams::validate() const {
  std::string e = slidingModeTable().checkRanges(*this);
  if (!e.empty()) return e;
  if (p % 2 == 0 || q % 2 == 0 || !(p > q && p < 2 * q))
    return "p/q = " + std::to_string(p) + "/" + std::to_string(q) +
           " must be a ratio of odd positive integers with 1 < p/q < 2";
  e = firstError({checkOrdered("m0_min", m0_min, "m0_max", m0_max), checkOrdered("i0_min", i0_min, "i0_max", i0_max)});
  if (!e.empty()) return e;
  if (m0_initial > 0.0) e = checkRange("m0_initial", m0_initial, m0_min, m0_max, "kg (the projection bounds)");
  if (e.empty() && i0_initial > 0.0)
    e = checkRange("i0_initial", i0_initial, i0_min, i0_max, "kg·m^2 (the projection bounds)");
  return e;
}

namespace {
/// The rates of m0_hat and I0_hat for the chosen reading. eq 4.22 adapts gamma_hat = m0_hat R and
/// alpha_hat = I0_hat R / L at the given rates: d m0_hat = d gamma_hat / R, d I0_hat = d alpha_hat L / R.
void estimateRates(const SlidingModeParams& p, double R, double L, double& rate_m, double& rate_i) {
  rate_m = p.adaptation == Adaptation::eq_4_22 ? p.rate_m / R : p.rate_m;
  rate_i = p.adaptation == Adaptation::eq_4_22 ? p.rate_i * L / R : p.rate_i;
}
}  // namespace

SlidingModeController::SlidingModeController(const SlidingModeParams& params, const RobotParams& nominal)
    : params_(params),
      R_(nominal.R),
      L_(nominal.L),
      m0_initial_(params.m0_initial > 0.0 ? params.m0_initial : nominal.m0()),
      i0_initial_(params.i0_initial > 0.0 ? params.i0_initial : nominal.I0()) {
  const std::string error = firstError({params.validate(), nominal.validate()});
  if (!error.empty()) throw std::invalid_argument(error);
  estimateRates(params_, R_, L_, rate_m_, rate_i_);
  exponent_ = static_cast<double>(params_.p) / params_.q;
  reset();
}

void SlidingModeController::reset() {
  linear_ = angular_ = Channel{};
  last_output_ = SlidingModeOutput{};
  m0_hat_ = m0_initial_;
  i0_hat_ = i0_initial_;
  if (params_.adaptive) {
    m0_hat_ = std::clamp(m0_hat_, params_.m0_min, params_.m0_max);
    i0_hat_ = std::clamp(i0_hat_, params_.i0_min, params_.i0_max);
  }
}

void SlidingModeController::setParams(const SlidingModeParams& params) {
  const std::string error = params.validate();
  if (!error.empty()) throw std::invalid_argument(error);
  params_ = params;
  estimateRates(params_, R_, L_, rate_m_, rate_i_);
  exponent_ = static_cast<double>(params_.p) / params_.q;
  if (params_.adaptive) {
    m0_hat_ = std::clamp(m0_hat_, params_.m0_min, params_.m0_max);
    i0_hat_ = std::clamp(i0_hat_, params_.i0_min, params_.i0_max);
  }
}

void SlidingModeController::heldBack(const WheelTorques& sent) {
  // Per wheel: +1 held below the output, -1 held above, 0 sent as computed.
  const auto held = [](double out, double got) { return got < out ? 1 : got > out ? -1 : 0; };
  const int r = held(last_output_.torques.right, sent.right), l = held(last_output_.torques.left, sent.left);
  // Which way each channel is blocked: v rises with both wheels, omega with the right and against the left.
  const auto mark = [](bool up, bool down) { return up && down ? 2 : up ? 1 : down ? -1 : 0; };
  linear_.held = mark(r > 0 || l > 0, r < 0 || l < 0);
  angular_.held = mark(r > 0 || l < 0, r < 0 || l > 0);
}

inline bool SlidingModeController::heldAgainst(Channel& c, double e) {
  const bool against = c.held == 2 || (c.held > 0 && e > 0.0) || (c.held < 0 && e < 0.0);
  c.held = 0;
  return against;
}

inline void SlidingModeController::surface(Channel& c, double e, double xd_dot, double beta, double dt, bool held,
                                           double& s, double& phi) const {
  if (!held) c.integral += e * dt;
  // S = e + beta (int e)^(p/q)  (eq 4.7).  The derivative term uses (int e)^(p/q - 1): for 1 < p/q < 2
  // its exponent (p-q)/q lies in (0, 1), so it is finite and equals 0 at int e = 0 (no division, no
  // singularity); only its own derivative would be unbounded there, and that never enters the law.
  double power_p, power_p_minus_q;  // (int e)^(p/q) and (int e)^((p-q)/q)
  if (params_.q == 3) {             // one cube root serves both powers (same values as realPower)
    const double root = std::cbrt(std::fabs(c.integral));
    // powerOfRoot's products, shared: root^p is root^(p-q) times root, q more times, in that order.
    const int p_minus_q = params_.p - params_.q;
    double mag = 1.0;
    for (int i = 0; i < p_minus_q; ++i) mag *= root;
    const double mag_p_minus_q = mag;
    mag = mag * root * root * root;
    const bool negative = c.integral < 0.0;
    power_p = (params_.p % 2 == 0 || !negative) ? mag : -mag;
    power_p_minus_q = (p_minus_q % 2 == 0 || !negative) ? mag_p_minus_q : -mag_p_minus_q;
  } else {
    power_p = realPower(c.integral, params_.p, params_.q);
    power_p_minus_q = realPower(c.integral, params_.p - params_.q, params_.q);
  }
  s = e + beta * power_p;
  phi = xd_dot + beta * exponent_ * e * power_p_minus_q;
}

// One named result on every path, so that it is built in the caller's slot (NRVO): with two, it was built on
// the stack and copied out, 16 bytes at a time, from fields just stored 8 (and 1) bytes at a time, loads
// that cannot be forwarded from those stores (~6 % of a benchmark run, perf annotate).
SlidingModeOutput SlidingModeController::update(const VelocityCommand& desired, double v, double omega, double dt) {
  SlidingModeOutput out;
  if (!allFinite(desired.v, desired.omega, desired.v_dot, desired.omega_dot, v, omega, dt) || !(dt > 0.0)) {
    out = last_output_;
    out.rejected = true;
    return out;
  }
  if (desired.hold) {  // a stop: frozen, the standstill hold brakes
    out.e_v = -v;
    out.e_omega = -omega;
    out.holding = true;
    last_output_ = out;
    return out;
  }
  out.e_v = desired.v - v;  // e = X_d - X: the sign eq 4.9 onwards uses (eq 4.5 prints X - X_d)
  out.e_omega = desired.omega - omega;
  double phi_v, phi_w;
  const bool held_v = heldAgainst(linear_, out.e_v), held_w = heldAgainst(angular_, out.e_omega);
  surface(linear_, out.e_v, desired.v_dot, params_.beta_v, dt, held_v, out.s_v, phi_v);
  surface(angular_, out.e_omega, desired.omega_dot, params_.beta_omega, dt, held_w, out.s_omega, phi_w);

  // eq 4.13 with gamma_hat = m0_hat R and alpha_hat = I0_hat R / L (eq 4.10).
  const double gamma_hat = m0_hat_ * R_, alpha_hat = i0_hat_ * R_ / L_;
  out.u1 = gamma_hat * phi_v + params_.k1 * out.s_v + params_.eta1 * params_.switching(out.s_v);
  out.u2 = alpha_hat * phi_w + params_.k2 * out.s_omega + params_.eta2 * params_.switching(out.s_omega);

  if (params_.adaptive) {
    // Adaptive law with the sign that makes the Lyapunov derivative (4.21) negative for e = X_d - X:
    // m0_hat' = +rate S1 phi1 (4.22 prints a minus). Euler step followed by the projection onto the
    // bounds, the discrete form of the discontinuous projection (Liu 2011).
    // rate_m_, rate_i_: params_.rate_m, rate_i themselves, or scaled for eq 4.22's gamma_hat, alpha_hat.
    if (!held_v) m0_hat_ = std::clamp(m0_hat_ + dt * rate_m_ * out.s_v * phi_v, params_.m0_min, params_.m0_max);
    if (!held_w) i0_hat_ = std::clamp(i0_hat_ + dt * rate_i_ * out.s_omega * phi_w, params_.i0_min, params_.i0_max);
  }

  const double right = 0.5 * (out.u1 + out.u2), left = 0.5 * (out.u1 - out.u2);
  out.torques.right = std::clamp(right, -params_.max_torque, params_.max_torque);
  out.torques.left = std::clamp(left, -params_.max_torque, params_.max_torque);
  const bool saturated = out.torques.right != right || out.torques.left != left;
  out.saturated = saturated;
  // last_output_ = out, field by field, the flags from the register (not a struct copy: see above).
  last_output_.torques.right = out.torques.right;
  last_output_.torques.left = out.torques.left;
  last_output_.e_v = out.e_v;
  last_output_.e_omega = out.e_omega;
  last_output_.s_v = out.s_v;
  last_output_.s_omega = out.s_omega;
  last_output_.u1 = out.u1;
  last_output_.u2 = out.u2;
  last_output_.saturated = saturated;
  last_output_.rejected = false;
  last_output_.holding = false;
  return out;
}

}  // namespace core
}  // namespace sowing_robot
