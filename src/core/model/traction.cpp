#include "sowing_robot/core/model/traction.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {
namespace {

constexpr double kGravity = 9.81;  // [m/s^2]

}  // namespace

const ParamTable<TractionParams>& tractionTable() {
  using T = TractionParams;
  static const ParamTable<T> table({
      flag("traction/enabled", &T::enabled, false,
           "wheel slip on: the plant integrates each wheel's spin and its soil force; off, today's no-slip plant"),
      number("traction/mu_peak", &T::mu_peak, 0.6, Limits::closed(0.0, 1000.0), "",
             "peak friction coefficient of the soil (about 0.2 wet grass, 0.35 dirt track, 0.6 loose moist soil; "
             "0 = ice; far above 1 only to approach the no-slip plant)"),
      number("traction/mu_slide", &T::mu_slide, 0.45, Limits::closed(0.0, 1000.0), "",
             "friction coefficient of a fully sliding wheel (|slip| >= 1); <= mu_peak"),
      number("traction/slip_peak", &T::slip_peak, 0.15, Limits{0.0, 1.0, true, true}, "",
             "longitudinal slip ratio at which the friction peaks"),
      number("traction/slip_stiffness", &T::slip_stiffness, 8.0, Limits::above(0.0, 1e6), "",
             "slope of friction coefficient over slip ratio at zero slip; >= mu_peak / slip_peak"),
      number(
          "traction/rolling_resistance", &T::rolling_resistance, 0.05, Limits::closed(0.0, 1.0), "",
          "rolling-resistance force / normal load, at each wheel and the caster (0.02 hard track .. 0.15 soft soil)"),
      number("traction/slip_speed_floor", &T::slip_speed_floor, 0.05, Limits::above(0.0, 1.0), "m/s",
             "smallest speed the slip ratio is divided by (regularises slip at standstill)"),
      number("traction/caster_x", &T::caster_x, 0.30, Limits::above(0.0, 5.0), "m",
             "caster contact ahead of the axle, for the normal loads (URDF caster_joint x)"),
      integer("traction/substeps", &T::substeps, 4, Limits::closed(1.0, 1000.0), "",
              "linearly implicit integration sub-steps per plant step"),
      number(
          "traction/draft_force", &T::draft_force, 0.0, Limits::closed(0.0, 1e5), "N",
          "draft of the seed drill's tool while it is down, at the tool point (URDF tool_link) against its "
          "motion, at the drill's nominal working depth (draft_depth) and speed (draft_speed) on the field's soil; 0 = "
          "none (a furrow opener in loose soil: some 10..100 N)"),
      number("traction/draft_depth", &T::draft_depth, 0.04, Limits::positive(), "m",
             "the seed drill's nominal working depth, the depth draft_force is for; the draft grows in proportion to "
             "the depth (ASABE D497), and the drill runs at this depth unless a depth control "
             "(torque_controller/hitch_control/depth_control) sets it shallower"),
      number("traction/draft_speed", &T::draft_speed, 1.0, Limits::positive(), "m/s",
             "the tool point's speed draft_force is for (the row speed)"),
      number("traction/draft_speed_linear", &T::draft_speed_linear, 0.0, Limits::closed(0.0, 100.0), "s/m",
             "the draft's linear rise with speed, B/A of ASABE D497's D = F (A + B S + C S^2) W T; 0: none (D497's "
             "seeding implements have B = C = 0; a tine opener tilling its slot has more)"),
      number("traction/draft_speed_quadratic", &T::draft_speed_quadratic, 0.0, Limits::closed(0.0, 100.0), "s^2/m^2",
             "the draft's quadratic rise with speed, C/A of ASABE D497's law (soil thrown aside); 0: none"),
      number("traction/tool_depth_min", &T::tool_depth_min, 0.01, Limits::nonNegative(), "m",
             "shallowest depth the seed drill can mechanically be set to (a depth asked for outside the range is "
             "clamped to it)"),
      number("traction/tool_depth_max", &T::tool_depth_max, 0.08, Limits::positive(), "m",
             "deepest depth the seed drill can mechanically be set to"),
  });
  return table;
}

TractionParams::TractionParams() { tractionTable().applyDefaults(*this); }

std::string TractionParams::validate() const {
  const std::string e = tractionTable().checkRanges(*this);
  if (!e.empty()) return e;
  if (mu_slide > mu_peak)
    return "traction/mu_slide = " + formatNumber(mu_slide) + " must be <= traction/mu_peak = " + formatNumber(mu_peak);
  if (slip_stiffness * slip_peak < mu_peak)
    return "traction/slip_stiffness = " + formatNumber(slip_stiffness) +
           " must be >= traction/mu_peak / traction/slip_peak = " + formatNumber(mu_peak / slip_peak);
  if (!(tool_depth_min < tool_depth_max))
    return "traction/tool_depth_min = " + formatNumber(tool_depth_min) +
           " must be below traction/tool_depth_max = " + formatNumber(tool_depth_max) +
           " (the drill's mechanical depth range)";
  if (draft_depth < tool_depth_min || draft_depth > tool_depth_max)
    return "traction/draft_depth = " + formatNumber(draft_depth) + " must lie in the drill's mechanical range [" +
           formatNumber(tool_depth_min) + ", " + formatNumber(tool_depth_max) + "] (traction/tool_depth_min, max)";
  return "";
}

double toolDraft(const TractionParams& p, double depth, double speed, double soil_factor) {
  // D497's speed polynomial relative to its value at the nominal speed (1 when b = c = 0, exactly).
  const double b = p.draft_speed_linear, c = p.draft_speed_quadratic, s = std::fabs(speed), s0 = p.draft_speed;
  const double shape = (1.0 + (b + c * s) * s) / (1.0 + (b + c * s0) * s0);
  return p.draft_force * soil_factor * (depth / p.draft_depth) * shape;
}

double tractionFriction(const TractionParams& p, double kappa, double* slope) {
  double s;
  const double mu = FrictionCurve(p).eval(std::fabs(kappa), s);
  if (slope) *slope = s;
  return kappa < 0.0 ? -mu : mu;
}

NormalLoads staticNormalLoads(const RobotParams& robot, double mass_scale, double caster_x) {
  const double weight = robot.m() * mass_scale * kGravity;
  // Moments about the axle: weight at mc d / m ahead of it, caster reaction at caster_x.
  const double caster = std::clamp(robot.mc * mass_scale * robot.d * kGravity / caster_x, 0.0, weight);
  return {0.5 * (weight - caster), 0.5 * (weight - caster), caster};
}

TractionPlant::TractionPlant(const RobotParams& nominal, const PlantDisturbance& disturbance,
                             const TractionParams& traction)
    : nominal_(nominal),
      disturbance_(disturbance),
      traction_(traction),
      curves_{FrictionCurve(traction)},
      rr_{traction.rolling_resistance},
      draft_factor_{1.0},
      tool_depth_(traction.draft_depth),
      rng_(disturbance.seed) {
  const std::string error = firstError({nominal.validate(), disturbance.validate(), traction.validate()});
  if (!error.empty()) throw std::invalid_argument(error);
  const double spin = 2.0 * nominal.Iw / (nominal.R * nominal.R);
  m_b_ = nominal.m0() * disturbance.mass_scale - spin;
  i_b_ = nominal.I0() * disturbance.inertia_scale - nominal.L * nominal.L * spin;
  mcd_ = nominal.mc * nominal.d * disturbance.mass_scale;
  if (!(m_b_ > 0.0) || !(i_b_ > 0.0))
    throw std::invalid_argument("traction plant: the mismatch leaves no body mass or yaw inertia beside the wheels");
  sqrt_m_ = std::sqrt(m_b_);
  sqrt_i_ = std::sqrt(i_b_);
  inv_sqrt_mi_ = 1.0 / (sqrt_m_ * sqrt_i_);
  inv_sqrt_m_ = 1.0 / sqrt_m_;
  inv_sqrt_i_ = 1.0 / sqrt_i_;
  inv_m_ = 1.0 / m_b_;
  inv_i_ = 1.0 / i_b_;
  inv_iw_ = 1.0 / nominal.Iw;
  inv_floor_ = 1.0 / traction.slip_speed_floor;
  const double R = nominal.R, L = nominal.L;
  slip_a_ = R * R * inv_iw_ + inv_m_ + L * L * inv_i_;
  slip_b_ = inv_m_ - L * L * inv_i_;
  loads_ = staticNormalLoads(nominal, disturbance.mass_scale, traction.caster_x);
}

void TractionPlant::setNormalLoads(const NormalLoads& loads) {
  if (!(loads.right >= 0.0) || !(loads.left >= 0.0) || !(loads.caster >= 0.0) ||
      !allFinite(loads.right, loads.left, loads.caster))
    throw std::invalid_argument("traction plant: normal loads must be finite and >= 0");
  loads_ = loads;
}

void TractionPlant::setSoil(const SoilMap& soil) {
  std::vector<FrictionCurve> curves{FrictionCurve(traction_)};
  std::vector<double> rr{traction_.rolling_resistance}, draft_factor{1.0};
  for (std::size_t i = 0; i < soil.patches().size(); ++i) {
    const SoilPatch& patch = soil.patches()[i];
    TractionParams p = traction_;
    p.mu_peak = patch.mu_peak;
    p.mu_slide = patch.mu_slide;
    p.rolling_resistance = patch.rolling_resistance;
    const std::string e = p.validate();
    if (!e.empty())
      throw std::invalid_argument("field/patches[" + std::to_string(i) + "] does not fit the slip curve: " + e);
    curves.emplace_back(p);
    rr.push_back(patch.rolling_resistance);
    draft_factor.push_back(patch.draft_factor);
  }
  soil_ = soil;
  curves_ = std::move(curves);
  rr_ = std::move(rr);
  draft_factor_ = std::move(draft_factor);
  ground_[0] = ground_[1] = ground_[2] = ground_tool_ = 0;
  locateContacts();
}

void TractionPlant::locateContacts() {
  if (soil_.empty()) return;
  double s, c;
  s = std::sin(state_[THETA]);
  c = std::cos(state_[THETA]);
  const double L = nominal_.L;
  const Eigen::Vector2d axle(state_[X], state_[Y]), left(-s * L, c * L);
  ground_[RIGHT] = 1 + soil_.patchAt(axle - left);
  ground_[LEFT] = 1 + soil_.patchAt(axle + left);
  ground_[kCaster] = 1 + soil_.patchAt(axle + traction_.caster_x * Eigen::Vector2d(c, s));
  if (traction_.draft_force > 0.0)
    ground_tool_ =
        1 + soil_.patchAt(axle + Eigen::Vector2d(c * tool_.x() - s * tool_.y(), s * tool_.x() + c * tool_.y()));
}

bool TractionPlant::setToolDepth(double depth) {
  if (!std::isfinite(depth)) return false;
  tool_depth_ = std::clamp(depth, traction_.tool_depth_min, traction_.tool_depth_max);
  return true;
}

void TractionPlant::reset(const State& initial, double t) {
  if (!initial.allFinite() || !std::isfinite(t)) throw std::invalid_argument("plant reset: non-finite state or time");
  state_ = initial;
  time_ = t;
  wheel_rate_[RIGHT] = (initial[V] + nominal_.L * initial[OMEGA]) / nominal_.R;
  wheel_rate_[LEFT] = (initial[V] - nominal_.L * initial[OMEGA]) / nominal_.R;
  slip_[RIGHT] = slip_[LEFT] = force_[RIGHT] = force_[LEFT] = 0.0;
  draft_f_ = draft_m_ = 0.0;
  motor_[RIGHT].reset();
  motor_[LEFT].reset();
  applied_[RIGHT] = applied_[LEFT] = 0.0;
  locateContacts();
  rng_.seed(disturbance_.seed);
  noise_.reset();
}

void TractionPlant::setMotor(const MotorParams& motor) {
  const std::string error = motor.validate();
  if (!error.empty()) throw std::invalid_argument(error);
  motor_[RIGHT] = motor_[LEFT] = WheelMotor(motor);
}

GripBudget gripBudget(const RobotParams& robot, double mass_scale, const TractionParams& traction, double mu_peak,
                      double mu_slide, double rolling_resistance) {
  const NormalLoads n = staticNormalLoads(robot, mass_scale, traction.caster_x);
  const double drive = n.right + n.left;
  GripBudget b;
  b.peak = mu_peak * drive;
  b.slide = mu_slide * drive;
  b.needed = rolling_resistance * (drive + n.caster) + traction.draft_force;
  return b;
}

GripBudget gripBudget(const RobotParams& robot, double mass_scale, const TractionParams& traction, double mu_peak,
                      double mu_slide, double rolling_resistance, double draft) {
  TractionParams t = traction;
  t.draft_force = draft;
  return gripBudget(robot, mass_scale, t, mu_peak, mu_slide, rolling_resistance);
}

std::vector<DraftCheck> checkFieldDraft(const RobotParams& robot, double mass_scale, const TractionParams& traction,
                                        const std::vector<SoilPatch>& patches, double depth) {
  std::vector<DraftCheck> out;
  if (!(traction.draft_force > 0.0)) return out;
  const double d = std::clamp(depth, traction.tool_depth_min, traction.tool_depth_max);
  const auto check = [&](int index, double mu_peak, double mu_slide, double rolling, double factor) {
    DraftCheck c;
    c.patch = index;
    c.depth = d;
    c.draft = toolDraft(traction, d, traction.draft_speed, factor);
    c.budget = gripBudget(robot, mass_scale, traction, mu_peak, mu_slide, rolling, c.draft);
    c.carried = c.budget.peak >= c.budget.needed;
    const double rolling_force = c.budget.needed - c.draft;
    char b[400];
    std::snprintf(b, sizeof b,
                  "%s (mu %.2f/%.2f, rolling resistance %.2f, draft factor %.2f): peak traction %.1f N (sliding %.1f "
                  "N) against %.1f N rolling + %.1f N draft at %.1f cm and %.2f m/s = %.1f N: %s %.1f N",
                  index < 0 ? "field soil" : ("soil patch " + std::to_string(index)).c_str(), mu_peak, mu_slide,
                  rolling, factor, c.budget.peak, c.budget.slide, rolling_force, c.draft, 100.0 * d,
                  traction.draft_speed, c.budget.needed,
                  c.carried ? "carries the drill, margin" : "cannot carry the drill even at its shallowest, short by",
                  std::fabs(c.budget.margin()));
    c.why = b;
    if (!c.carried)
      c.why += rolling_force > c.budget.peak ? " (not even the rolling resistance: the robot cannot cross it)"
                                             : " (the tool must be lifted there: that stretch goes unsown)";
    out.push_back(c);
  };
  check(-1, traction.mu_peak, traction.mu_slide, traction.rolling_resistance, 1.0);
  for (std::size_t i = 0; i < patches.size(); ++i)
    check(static_cast<int>(i), patches[i].mu_peak, patches[i].mu_slide, patches[i].rolling_resistance,
          patches[i].draft_factor);
  return out;
}

std::string fieldDraftWarnings(const std::vector<DraftCheck>& checks) {
  std::string out;
  for (const DraftCheck& c : checks)
    if (!c.carried) out += (out.empty() ? "" : "\n") + c.why;
  return out;
}

std::string gripDiagnosis(const RobotParams& robot, double mass_scale, const TractionParams& traction,
                          const SoilMap& soil, const Eigen::Vector2d& where) {
  const int i = soil.patchAt(where);
  const SoilPatch* p = i >= 0 ? &soil.patches()[static_cast<std::size_t>(i)] : nullptr;
  const GripBudget g =
      gripBudget(robot, mass_scale, traction, p ? p->mu_peak : traction.mu_peak, p ? p->mu_slide : traction.mu_slide,
                 p ? p->rolling_resistance : traction.rolling_resistance);
  char b[200];
  std::snprintf(b, sizeof(b), "%s grip budget: peak traction %.1f N (sliding %.1f N) against %.1f N needed",
                i >= 0 ? ("soil patch " + std::to_string(i)).c_str() : "field soil", g.peak, g.slide, g.needed);
  return b;
}

double TractionPlant::kineticEnergy() const {
  const double v = state_[V], w = state_[OMEGA];
  return 0.5 * (m_b_ * v * v + i_b_ * w * w +
                nominal_.Iw * (wheel_rate_[RIGHT] * wheel_rate_[RIGHT] + wheel_rate_[LEFT] * wheel_rate_[LEFT]));
}

bool TractionPlant::step(double tau_right, double tau_left, double dt) {
  if (!allFinite(tau_right, tau_left, dt) || !(dt > 0.0)) return false;
  double noise_r = 0.0, noise_l = 0.0;
  if (disturbance_.noise_std > 0.0) {
    noise_r = disturbance_.noise_std * noise_(rng_);
    noise_l = disturbance_.noise_std * noise_(rng_);
  }
  const int n = traction_.substeps;
  const double h = dt / n;
  // The sinusoid at each sub-step's midpoint (second order in the impulse).
  double dist_s = 0.0, dist_c = 0.0;
  if (disturbance_.sinusoidal) {
    const double angle = disturbance_.frequency * (time_ + 0.5 * h);
    dist_s = std::sin(angle);
    dist_c = std::cos(angle);
  }
  const double amplitude = disturbance_.sinusoidal ? disturbance_.amplitude : 0.0;
  locateContacts();
  double rr_force, rr_moment;
  rollingResistance(rr_force, rr_moment);
  draft_f_ = draft_m_ = 0.0;
  if (tool_down_ && traction_.draft_force > 0.0) {
    draft(dt, draft_f_, draft_m_);
    rr_force += draft_f_;
    rr_moment += draft_m_;
  }
  const bool motors = motor_[RIGHT].params().enabled;
  applied_[RIGHT] = tau_right;
  applied_[LEFT] = tau_left;
  for (int j = 0; j < n; ++j) {
    if (motors) {  // at the wheels' own spin rates, each sub-step
      applied_[RIGHT] = motor_[RIGHT].apply(tau_right, wheel_rate_[RIGHT], h);
      applied_[LEFT] = motor_[LEFT].apply(tau_left, wheel_rate_[LEFT], h);
    }
    substep(applied_[RIGHT] + noise_r + amplitude * dist_s, applied_[LEFT] + noise_l + amplitude * dist_c, rr_force,
            rr_moment, h);
    if (disturbance_.sinusoidal && j + 1 < n) {  // the next sub-step's midpoint
      const double angle = disturbance_.frequency * (time_ + (j + 1.5) * h);
      dist_s = std::sin(angle);
      dist_c = std::cos(angle);
    }
  }
  time_ += dt;
  return true;
}

void TractionPlant::rollingResistance(double& force, double& moment) const {
  // Non-stiff (rate c N / (floor m) of a few 1/s): once per step, from the step's start.
  force = moment = 0.0;
  const double c_r = rr_[ground_[RIGHT]], c_l = rr_[ground_[LEFT]], c_rr = rr_[ground_[kCaster]];
  if (c_r <= 0.0 && c_l <= 0.0 && c_rr <= 0.0) return;
  const double v = state_[V], w = state_[OMEGA], L = nominal_.L;
  const double f_r = -c_r * loads_.right * std::clamp((v + L * w) * inv_floor_, -1.0, 1.0);
  const double f_l = -c_l * loads_.left * std::clamp((v - L * w) * inv_floor_, -1.0, 1.0);
  force = f_r + f_l;
  moment = L * (f_r - f_l);
  // Caster: against its travel (v, caster_x w); the sideways part goes into the axle's nonholonomic
  // reaction, its moment about the axle stays.
  if (loads_.caster > 0.0 && c_rr > 0.0) {
    const double xc = traction_.caster_x, lateral = xc * w;
    const double speed = std::sqrt(v * v + lateral * lateral);
    const double scale = c_rr * loads_.caster / std::max(speed, traction_.slip_speed_floor);
    force -= scale * v;
    moment -= scale * lateral * xc;
  }
}

namespace {
constexpr double kDraftRestSpeed = 1e-150;  // [m/s] below it the tool's damper sees the robot at rest
}  // namespace

void TractionPlant::draft(double dt, double& force, double& moment) const {
  const double xt = tool_.x(), yt = tool_.y(), v = state_[V], w = state_[OMEGA];
  const double vx = v - w * yt, vy = w * xt, speed = std::hypot(vx, vy);
  const double D = toolDraft(traction_, tool_depth_, speed, draft_factor_[ground_tool_]),
               floor = traction_.slip_speed_floor;
  // Force = −c (vx, vy), c = D / max(speed, floor): full D when moving, a linear damper below the floor.
  // Stiff when D is large against the body (c dt / m >> 1), so semi-implicit, with the tool point's
  // mobility along the motion, M = (vx²/m + (xt vy − yt vx)²/I) / speed²: c / (1 + dt c M) cannot reverse
  // the motion in one step, and a draft the motors cannot overcome brings the robot to rest. At speed the
  // factor is 1 + O(dt D / (m v)) (7e-4 for 10 N at 1 m/s).
  // At rest, and at speeds so small that speed² below would underflow to 0 (the mobility then 0 / 0: a robot held
  // still with the tool down decays towards 1e-164 m/s in some 5 s and went NaN, seen in no_traction.test), the
  // damper's force, c speed < 1e-148 N, is none.
  if (!(speed > kDraftRestSpeed)) {
    force = moment = 0.0;
    return;
  }
  const double c = D / std::max(speed, floor);
  const double lever = xt * vy - yt * vx;
  const double mobility = (vx * vx * inv_m_ + lever * lever * inv_i_) / (speed * speed);
  const double scale = c / (1.0 + dt * c * mobility);
  const double fx = -scale * vx, fy = -scale * vy;
  force = fx;
  moment = xt * fy - yt * fx;
}

void TractionPlant::substep(double tau_r, double tau_l, double rr_force, double rr_moment, double h) {
  const double R = nominal_.R, L = nominal_.L, floor = traction_.slip_speed_floor;
  const double v = state_[V], w = state_[OMEGA];
  const double u[2] = {v + L * w, v - L * w};
  const double n_load[2] = {loads_.right, loads_.left};
  const double tau[2] = {tau_r, tau_l};
  double f0[2], k[2];
  for (int i = 0; i < 2; ++i) {
    const double rim = R * wheel_rate_[i], s = rim - u[i];
    const double den = std::max({std::fabs(u[i]), std::fabs(rim), floor});
    const double inv_den = 1.0 / den, kappa = s * inv_den;
    // dF/ds for the implicit part. Up to the peak, the larger of the tangent and the secant F/s: the
    // tangent alone lets a very stiff soil overshoot past zero slip (the curve is concave, its tangent
    // too flat) and chatter. Past the peak the tangent is negative and small: that branch stays
    // explicit (slope 0), which keeps the 2×2 system below well posed and the sliding wheel accurate.
    // Any non-negative slope keeps the linearly implicit Euler step first-order consistent.
    double jac;
    const double mu = curves_[ground_[i]].evalForIntegration(std::fabs(kappa), jac);
    f0[i] = kappa < 0.0 ? -n_load[i] * mu : n_load[i] * mu;
    k[i] = n_load[i] * jac * inv_den;
    slip_[i] = kappa;
  }
  const double inv_m = inv_m_, inv_i = inv_i_, inv_iw = inv_iw_;
  // Body accelerations of the contact forces; the COM coupling (mc d w², −mc d w v) comes after, as a
  // rotation that does no work.
  const double av0 = (f0[RIGHT] + f0[LEFT] + rr_force) * inv_m;
  const double aw0 = (L * (f0[RIGHT] - f0[LEFT]) + rr_moment) * inv_i;
  // Explicit change of each slip velocity over the sub-step, then the implicit correction:
  // (1 + h A k_i) ds_i + h B k_j ds_j = b_i, A = R²/Iw + 1/m + L²/I, B = 1/m - L²/I (wheel j's force
  // change reaches wheel i's slip through the body's translation and yaw).
  // The slip prediction sees the coupling's accelerations too (else a stiff soil would fight the
  // rotation's velocity change every sub-step).
  const double av_slip = av0 + mcd_ * w * w * inv_m, aw_slip = aw0 - mcd_ * w * v * inv_i;
  const double b_r = h * (R * (tau[RIGHT] - R * f0[RIGHT]) * inv_iw - av_slip - L * aw_slip);
  const double b_l = h * (R * (tau[LEFT] - R * f0[LEFT]) * inv_iw - av_slip + L * aw_slip);
  const double A = slip_a_, B = slip_b_;
  const double m11 = 1.0 + h * A * k[RIGHT], m12 = h * B * k[LEFT];
  const double m21 = h * B * k[RIGHT], m22 = 1.0 + h * A * k[LEFT];
  const double inv_det = 1.0 / (m11 * m22 - m12 * m21);  // > 0: A > |B|, k >= 0
  const double ds_r = (m22 * b_r - m12 * b_l) * inv_det, ds_l = (m11 * b_l - m21 * b_r) * inv_det;
  // Forces at the sub-step's end, capped by the peak grip (the linearisation may overshoot the peak).
  double f[2];
  const double mu_r = curves_[ground_[RIGHT]].mu_p, mu_l = curves_[ground_[LEFT]].mu_p;
  f[RIGHT] = std::clamp(f0[RIGHT] + k[RIGHT] * ds_r, -mu_r * n_load[RIGHT], mu_r * n_load[RIGHT]);
  f[LEFT] = std::clamp(f0[LEFT] + k[LEFT] * ds_l, -mu_l * n_load[LEFT], mu_l * n_load[LEFT]);
  force_[RIGHT] = f[RIGHT];
  force_[LEFT] = f[LEFT];
  // One force for both sides of the contact: wheel and body exchange exactly the same momentum.
  const double av = av0 + (f[RIGHT] - f0[RIGHT] + f[LEFT] - f0[LEFT]) * inv_m;
  const double aw = aw0 + L * (f[RIGHT] - f0[RIGHT] - f[LEFT] + f0[LEFT]) * inv_i;
  double v1 = v + h * av, w1 = w + h * aw;
  // The coupling of eq 3.54 turns (√m v, √I w) at the rate mc d w / √(m I) and keeps their length: an
  // exact rotation (rate frozen at the sub-step's start) conserves the kinetic energy as the ODE does.
  if (mcd_ != 0.0) {
    double c, sn;
    const double angle = mcd_ * w * h * inv_sqrt_mi_;
    sn = std::sin(angle);
    c = std::cos(angle);
    const double a = sqrt_m_ * v1, b = sqrt_i_ * w1;
    v1 = (a * c + b * sn) * inv_sqrt_m_;
    w1 = (b * c - a * sn) * inv_sqrt_i_;
  }
  double rate1[2];
  for (int i = 0; i < 2; ++i) rate1[i] = wheel_rate_[i] + h * (tau[i] - R * f[i]) * inv_iw;
  // Kinematics (eq 3.13) with the mean velocities, heading at the sub-step's midpoint.
  const double dtheta = 0.5 * h * (w + w1);
  const double mid = state_[THETA] + 0.5 * dtheta;
  const double sm = std::sin(mid), cm = std::cos(mid);
  const double ds = 0.5 * h * (v + v1);
  state_[X] += ds * cm;
  state_[Y] += ds * sm;
  state_[THETA] += dtheta;
  state_[V] = v1;
  state_[OMEGA] = w1;
  state_[PHI_R] += 0.5 * h * (wheel_rate_[RIGHT] + rate1[RIGHT]);
  state_[PHI_L] += 0.5 * h * (wheel_rate_[LEFT] + rate1[LEFT]);
  wheel_rate_[RIGHT] = rate1[RIGHT];
  wheel_rate_[LEFT] = rate1[LEFT];
}

}  // namespace core
}  // namespace sowing_robot
