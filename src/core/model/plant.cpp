#include "sowing_robot/core/model/plant.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/numerics/lanes2.h"
#include "sowing_robot/core/numerics/rotation.h"
#include "sowing_robot/core/numerics/trig.h"

// The step's pieces are called from two steps (one plant, two plants); GCC inlines them into the first but
// left them as calls in the second (perf: ~15 % of a benchmark run in the calls' overhead).
#if defined(__GNUC__)
#define SOWING_INLINE inline __attribute__((always_inline))
#define SOWING_LAMBDA_INLINE __attribute__((always_inline))
#else
#define SOWING_INLINE inline
#define SOWING_LAMBDA_INLINE
#endif

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
  double s, c;
  sinCos(angle, s, c);
  right = amplitude * s;
  left = amplitude * c;
}

}  // namespace

void Plant::sinusoidalDisturbance(double t, double& right, double& left) const {
  sinusoid(disturbance_, t, right, left);
}

State Plant::derivative(const State& s, double applied_right, double applied_left) const {
  double c, sn;
  sinCos(s[THETA], sn, c);
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

SOWING_INLINE void Plant::disturbanceAt(double t, double& right, double& left) {
  // RK4 asks for three times per step (t, t + h/2 twice, t + h) and the next step starts where this one
  // ended: remembering the last time evaluated halves the sin/cos calls, with bit-identical values.
  if (t != cached_disturbance_time_) {
    sinusoid(disturbance_, t, cached_disturbance_right_, cached_disturbance_left_);
    cached_disturbance_time_ = t;
  }
  right = cached_disturbance_right_;
  left = cached_disturbance_left_;
}

SOWING_INLINE void Plant::disturbancePairAt(Plant& a, double ta, Plant& b, double tb, double& right_a, double& left_a,
                                            double& right_b, double& left_b) {
  if constexpr (kHaveLanes2) {
    // Both due (the usual case at t + h/2 and t + h): sinusoid's operations on both angles at once, each
    // lane the scalar sinCos's bits (test_trig), stored in the caches that disturbanceAt then reads.
    const PlantDisturbance &da = a.disturbance_, &db = b.disturbance_;
    if (da.sinusoidal && db.sinusoidal && ta != a.cached_disturbance_time_ && tb != b.cached_disturbance_time_) {
      Lanes2 s, c;
      sinCos(Lanes2(da.frequency * ta, db.frequency * tb), s, c);
      a.cached_disturbance_right_ = da.amplitude * s.first();
      a.cached_disturbance_left_ = da.amplitude * c.first();
      b.cached_disturbance_right_ = db.amplitude * s.second();
      b.cached_disturbance_left_ = db.amplitude * c.second();
      a.cached_disturbance_time_ = ta;
      b.cached_disturbance_time_ = tb;
    }
  }
  a.disturbanceAt(ta, right_a, left_a);
  b.disturbanceAt(tb, right_b, left_b);
}

bool Plant::step(double tau_right, double tau_left, double dt) {
  double c, s;
  sinCos(state_[THETA], s, c);
  return stepWithHeading(tau_right, tau_left, dt, c, s);
}

bool Plant::step(double tau_right, double tau_left, double dt, double theta, double cos_theta, double sin_theta) {
  // Bit pattern, not ==: -0.0 == 0.0, but their sines differ in sign.
  if (std::memcmp(&theta, &state_[THETA], sizeof theta) == 0)
    return stepWithHeading(tau_right, tau_left, dt, cos_theta, sin_theta);
  return step(tau_right, tau_left, dt);
}

namespace {

// The rates of one RK4 stage (eq 3.13, 3.54) on plain numbers: the same operations, in the same order, as
// derivativeWithHeading() on the Eigen state, without the temporaries. Wheel angles never enter a
// derivative, so the stage states only carry x, y, theta, v, omega. N: double (one plant) or Lanes2 (two
// plants at once, stepPair), so both have the very same arithmetic.
template <typename N>
struct Rates {
  N x, y, theta, v, omega, phi_r, phi_l;
};

template <typename N>
struct PlantCoefficients {
  N mcd, m0, i0, R, L;
};

template <typename N>
SOWING_INLINE Rates<N> stageRates(const PlantCoefficients<N>& p, N v, N w, N cos_heading, N sin_heading,
                                  N applied_right, N applied_left) {
  const N u1 = applied_right + applied_left, u2 = applied_right - applied_left;
  Rates<N> k;
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
template <typename N, typename Stage>
SOWING_INLINE void rk4Increment(N v0, N w0, double h, const Stage& stage, Rates<N>& increment) {
  const N half(0.5 * h), whole(h), two(2.0);
  const Rates<N> k1 = stage(0, v0, w0, N(0.0));
  const Rates<N> k2 = stage(1, v0 + half * k1.v, w0 + half * k1.omega, half * k1.theta);
  const Rates<N> k3 = stage(2, v0 + half * k2.v, w0 + half * k2.omega, half * k2.theta);
  const Rates<N> k4 = stage(3, v0 + whole * k3.v, w0 + whole * k3.omega, whole * k3.theta);
  const N sixth(h / 6.0);
  auto combine = [&](N a, N b, N c, N d) { return sixth * (a + two * b + two * c + d); };
  increment.x = combine(k1.x, k2.x, k3.x, k4.x);
  increment.y = combine(k1.y, k2.y, k3.y, k4.y);
  increment.theta = combine(k1.theta, k2.theta, k3.theta, k4.theta);
  increment.v = combine(k1.v, k2.v, k3.v, k4.v);
  increment.omega = combine(k1.omega, k2.omega, k3.omega, k4.omega);
  increment.phi_r = combine(k1.phi_r, k2.phi_r, k3.phi_r, k4.phi_r);
  increment.phi_l = combine(k1.phi_l, k2.phi_l, k3.phi_l, k4.phi_l);
}

}  // namespace

SOWING_INLINE void Plant::drawNoise(double& right, double& left) {
  right = left = 0.0;
  if (disturbance_.noise_std > 0.0) {
    right = disturbance_.noise_std * noise_.next();
    left = disturbance_.noise_std * noise_.next();
  }
}

SOWING_INLINE void Plant::addIncrement(double x, double y, double theta, double v, double omega, double phi_r,
                                       double phi_l, double dt) {
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
  // The sinusoid is evaluated at each RK4 stage time; command and noise are held over the step.
  // Stages 2 and 3 share t + h/2, and stage 4's t + h is the next step's stage 1 (disturbanceAt).
  // The heading's cos/sin come from one sincos at the start of the step, turned by each stage's small
  // heading increment (rotateHeading), instead of a sincos per stage.
  const double t = time_, h = dt;
  const double applied_r0 = tau_right + noise_r, applied_l0 = tau_left + noise_l;
  const PlantCoefficients<double> p{mcd_, m0_, i0_, nominal_.R, nominal_.L};
  auto stage = [&](int k, double v, double w, double heading_increment) {
    double dr, dl, c, sn;
    disturbanceAt(stageTime(t, h, k), dr, dl);
    rotateHeading(cos0, sin0, heading_increment, c, sn);
    return stageRates(p, v, w, c, sn, applied_r0 + dr, applied_l0 + dl);
  };
  Rates<double> d;
  rk4Increment(state_[V], state_[OMEGA], h, stage, d);
  addIncrement(d.x, d.y, d.theta, d.v, d.omega, d.phi_r, d.phi_l, dt);
  return true;
}

void Plant::stepPair(Plant& a, const HeadingStep& in_a, Plant& b, const HeadingStep& in_b, double dt) {
  const auto alone = [dt](Plant& plant, const HeadingStep& in) {
    plant.step(in.tau_right, in.tau_left, dt, in.theta, in.cos_theta, in.sin_theta);
  };
  const auto takes = [dt](const HeadingStep& in) { return allFinite(in.tau_right, in.tau_left, dt) && dt > 0.0; };
  if constexpr (!kHaveLanes2) {
    alone(a, in_a);
    alone(b, in_b);
  } else {
    // One lane's numbers are the other plant's only if the wheel geometry is shared; a refused input
    // takes the one-plant path, which refuses it.
    if (!(takes(in_a) && takes(in_b) && a.nominal_.R == b.nominal_.R && a.nominal_.L == b.nominal_.L)) {
      alone(a, in_a);
      alone(b, in_b);
      return;
    }
    // step()'s choice of cos/sin: the caller's when theta is the state's heading to the bit, else computed.
    const auto heading = [](const Plant& plant, const HeadingStep& in, double& c, double& s) {
      if (std::memcmp(&in.theta, &plant.state_[THETA], sizeof in.theta) == 0) {
        c = in.cos_theta;
        s = in.sin_theta;
      } else {
        sinCos(plant.state_[THETA], s, c);
      }
    };
    double cos_a, sin_a, cos_b, sin_b;
    heading(a, in_a, cos_a, sin_a);
    heading(b, in_b, cos_b, sin_b);
    double noise_ra, noise_la, noise_rb, noise_lb;
    a.drawNoise(noise_ra, noise_la);
    b.drawNoise(noise_rb, noise_lb);
    const double ta = a.time_, tb = b.time_, h = dt;
    const Lanes2 cos0(cos_a, cos_b), sin0(sin_a, sin_b);
    const Lanes2 applied_r0(in_a.tau_right + noise_ra, in_b.tau_right + noise_rb);
    const Lanes2 applied_l0(in_a.tau_left + noise_la, in_b.tau_left + noise_lb);
    const PlantCoefficients<Lanes2> p{Lanes2(a.mcd_, b.mcd_), Lanes2(a.m0_, b.m0_), Lanes2(a.i0_, b.i0_),
                                      Lanes2(a.nominal_.R), Lanes2(a.nominal_.L)};
    auto stage = [&](int k, Lanes2 v, Lanes2 w, Lanes2 heading_increment) SOWING_LAMBDA_INLINE {
      double dra, dla, drb, dlb;
      disturbancePairAt(a, stageTime(ta, h, k), b, stageTime(tb, h, k), dra, dla, drb, dlb);
      Lanes2 c, sn;
      const double inc_a = heading_increment.first(), inc_b = heading_increment.second();
      if (std::fabs(inc_a) <= 0.05 && std::fabs(inc_b) <= 0.05) {  // rotateHeading's series, both lanes
        rotateBySeries(cos0, sin0, heading_increment, c, sn);
      } else {
        double ca, sa, cb, sb;
        rotateHeading(cos_a, sin_a, inc_a, ca, sa);
        rotateHeading(cos_b, sin_b, inc_b, cb, sb);
        c = Lanes2(ca, cb);
        sn = Lanes2(sa, sb);
      }
      return stageRates(p, v, w, c, sn, applied_r0 + Lanes2(dra, drb), applied_l0 + Lanes2(dla, dlb));
    };
    Rates<Lanes2> d;
    rk4Increment(Lanes2(a.state_[V], b.state_[V]), Lanes2(a.state_[OMEGA], b.state_[OMEGA]), h, stage, d);
    a.addIncrement(d.x.first(), d.y.first(), d.theta.first(), d.v.first(), d.omega.first(), d.phi_r.first(),
                   d.phi_l.first(), dt);
    b.addIncrement(d.x.second(), d.y.second(), d.theta.second(), d.v.second(), d.omega.second(), d.phi_r.second(),
                   d.phi_l.second(), dt);
  }
}

Eigen::Vector2d Plant::centreOfMass() const {
  return Eigen::Vector2d(state_[X], state_[Y]) + nominal_.d * unitVector(state_[THETA]);
}

}  // namespace core
}  // namespace sowing_robot
