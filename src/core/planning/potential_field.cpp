#include "sowing_robot/core/planning/potential_field.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

namespace {
constexpr double kStopSpeed = 1e-4;  ///< below this speed [m/s] theta is held
constexpr double kGridSlack = 1e-9;  ///< a call within 1 ns of a grid point is that grid point [s]

std::string indexed(const std::string& name, std::size_t i) { return name + "[" + std::to_string(i) + "]"; }

void validateObstacles(const std::vector<Obstacle>& obstacles) {
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const std::string e = obstacles[i].validate();
    if (!e.empty()) throw std::invalid_argument(indexed("obstacles", i) + ": " + e);
  }
}
}  // namespace

std::string RowLine::validate() const {
  if (!allFinite(x0, y0, heading))
    return "row start (" + std::to_string(x0) + ", " + std::to_string(y0) + ") and heading must be finite";
  return checkPositive("speed", speed, "m/s");
}

const ParamTable<PotentialFieldParams>& potentialFieldTable() {
  using P = PotentialFieldParams;
  static const ParamTable<P> table({
      number("alpha", &P::alpha, 4.0, Limits::positive(), "1/s^2", "position gain alpha (thesis 4)"),
      number("beta", &P::beta, 16.0, Limits::positive(), "1/s",
             "damping of the velocity relative to the target (thesis 16; 2 sqrt(alpha) is critical, README)"),
      number("influence_distance", &P::influence_distance, 0.5, Limits::positive(), "m",
             "d: no repulsion beyond this clearance from the obstacle surface (thesis 0.5)"),
      number("gain", &P::gain, 5.0, Limits::nonNegative(), "m^2/s^2",
             "k: radial repulsion -k grad V_a; 0 disables avoidance (not given in the thesis)"),
      number("tangential_ratio", &P::tangential_ratio, 1.0, Limits::nonNegative(), "",
             "|tangential| / |radial| repulsion"),
      flag("nearest_side", &P::nearest_side, true,
           "pass each obstacle on the side the reference is on when it enters the zone"),
      choice("avoid_side", &P::avoid_side, AvoidSide::kLeft, {{"left", AvoidSide::kLeft}, {"right", AvoidSide::kRight}},
             "forced side (nearest_side false) and tie-break on the line"),
      number("side_band", &P::side_band, 0.05, Limits::nonNegative(), "m",
             "half-width of the tie band around the obstacle centre"),
      number("core_fraction", &P::core_fraction, 0.1, Limits::closed(1e-3, 0.9), "",
             "below this fraction of d the potential continues linearly"),
      number("step", &P::step, 1e-3, Limits::closed(1e-6, 1e-3), "s", "internal RK4 step"),
      number("heading_hold_speed", &P::heading_hold_speed, 0.02, Limits::nonNegative(), "m/s",
             "below this speed (reference and target) theta is held"),
  });
  return table;
}

PotentialFieldParams::PotentialFieldParams() { potentialFieldTable().applyDefaults(*this); }

std::string PotentialFieldParams::validate() const { return potentialFieldTable().checkRanges(*this); }

LineTarget::LineTarget(const RowLine& row) : row_(row), u_(unitVector(row.heading)) {}

TargetState LineTarget::at(double t) const {
  TargetState s;
  const double tc = t > 0.0 ? t : 0.0;
  s.p = Eigen::Vector2d(row_.x0, row_.y0) + (row_.speed * tc) * u_;
  s.v = row_.speed * u_;
  s.heading = row_.heading;
  s.tool_down = true;
  return s;
}

PotentialField::PotentialField(const PotentialFieldParams& params, const RowLine& row, std::vector<Obstacle> obstacles)
    : PotentialField(
          params,
          [&row]() -> std::unique_ptr<TargetTrajectory> {
            const std::string e = row.validate();
            if (!e.empty()) throw std::invalid_argument("RowLine: " + e);
            return std::make_unique<LineTarget>(row);
          }(),
          std::move(obstacles)) {}

PotentialField::PotentialField(const PotentialFieldParams& params, std::unique_ptr<TargetTrajectory> target,
                               std::vector<Obstacle> obstacles)
    : params_(params), target_(std::move(target)), obstacles_(std::move(obstacles)) {
  const std::string e = params_.validate();
  if (!e.empty()) throw std::invalid_argument("PotentialFieldParams: " + e);
  if (!target_) throw std::invalid_argument("PotentialField: target is empty");
  validateObstacles(obstacles_);
  reset();
}

PotentialField::PotentialField(const PotentialField& o)
    : params_(o.params_),
      target_(o.target_->clone()),
      obstacles_(o.obstacles_),
      sides_(o.sides_),
      state_(o.state_),
      steps_(o.steps_),
      last_theta_(o.last_theta_),
      out_p_(o.out_p_),
      out_v_(o.out_v_),
      out_a_(o.out_a_) {}

PotentialField& PotentialField::operator=(const PotentialField& o) {
  if (this != &o) {
    PotentialField copy(o);
    *this = std::move(copy);
  }
  return *this;
}

void PotentialField::restart() {
  state_ = ErrorState{};
  steps_ = 0;
  const TargetState t0 = target_->at(0.0);
  last_theta_ = t0.heading;
  out_p_ = t0.p;
  out_v_ = t0.v;
  out_a_ = t0.a;
  sides_.assign(obstacles_.size(), 0);
  updateSides(t0.p, t0);
}

std::unique_ptr<ReferenceSource> PotentialField::clone() const {
  auto c = std::make_unique<PotentialField>(*this);
  c->reset();
  return c;
}

void PotentialField::setGains(double alpha, double beta, double gain, double tangential_ratio) {
  PotentialFieldParams p = params_;
  p.alpha = alpha;
  p.beta = beta;
  p.gain = gain;
  p.tangential_ratio = tangential_ratio;
  const std::string error = p.validate();
  if (!error.empty()) throw std::invalid_argument(error);
  params_ = p;
}

void PotentialField::setObstacles(std::vector<Obstacle> obstacles) {
  validateObstacles(obstacles);
  obstacles_ = std::move(obstacles);
  sides_.assign(obstacles_.size(), 0);
  const double t = static_cast<double>(steps_) * params_.step;
  const TargetState tgt = target_->at(t);
  updateSides(tgt.p + state_.e, tgt);
}

void PotentialField::setTarget(std::unique_ptr<TargetTrajectory> target) {
  if (!target) throw std::invalid_argument("PotentialField: target is empty");
  const double t = gridTime();
  const TargetState a = target_->at(t), b = target->at(t);
  state_.e += a.p - b.p;
  state_.ed += a.v - b.v;
  target_ = std::move(target);
  if (!obstacles_.empty()) updateSides(b.p + state_.e, b);
}

double PotentialField::sideFor(std::size_t i, const Eigen::Vector2d& p, const TargetState& target) const {
  const double fixed = params_.avoid_side == AvoidSide::kLeft ? 1.0 : -1.0;
  if (!params_.nearest_side) return fixed;
  if (sides_[i] != 0) return sides_[i];
  // A neighbour whose zone the reference is in already has a side: share it (no squeezing between).
  const double d = params_.influence_distance;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  int count = 0;
  for (std::size_t j = 0; j < obstacles_.size(); ++j) {
    const Obstacle& o = obstacles_[j];
    if (std::hypot(p.x() - o.x, p.y() - o.y) - o.radius >= d && j != i) continue;
    if (sides_[j] != 0) return sides_[j];
    centroid += Eigen::Vector2d(o.x, o.y);
    ++count;
  }
  centroid /= count;
  const Eigen::Vector2d u = unitVector(target.heading), left(-u.y(), u.x());
  const double offset = (p - centroid).dot(left);
  if (offset > params_.side_band) return 1.0;
  if (offset < -params_.side_band) return -1.0;
  return fixed;
}

void PotentialField::updateSides(const Eigen::Vector2d& p, const TargetState& target) {
  const double d = params_.influence_distance;
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const Obstacle& o = obstacles_[i];
    if (std::hypot(p.x() - o.x, p.y() - o.y) - o.radius >= d) sides_[i] = 0;
  }
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const Obstacle& o = obstacles_[i];
    if (sides_[i] == 0 && std::hypot(p.x() - o.x, p.y() - o.y) - o.radius < d)
      sides_[i] = static_cast<signed char>(sideFor(i, p, target));
  }
}

void PotentialField::clearanceDerivatives(double rho, double& dv, double& ddv) const {
  const double d = params_.influence_distance;
  dv = ddv = 0.0;
  if (rho >= d) return;
  const double rho_core = params_.core_fraction * d;
  const double r = rho > rho_core ? rho : rho_core;
  // V = (1/2 (d/r - 1))^2 = (d/r - 1)^2 / 4.
  const double q = d / r - 1.0;
  dv = -0.5 * q * d / (r * r);
  if (rho > rho_core) ddv = 0.5 * (3.0 * d * d / (r * r * r * r) - 2.0 * d / (r * r * r));
}

double PotentialField::repulsivePotential(const Eigen::Vector2d& p) const {
  const double d = params_.influence_distance;
  const double rho_core = params_.core_fraction * d;
  double v = 0.0;
  for (const Obstacle& o : obstacles_) {
    const double rho = std::hypot(p.x() - o.x, p.y() - o.y) - o.radius;
    if (rho >= d) continue;
    if (rho > rho_core) {
      const double q = d / rho - 1.0;
      v += 0.25 * q * q;
    } else {  // linear continuation below the core clearance
      const double q = d / rho_core - 1.0;
      const double slope = -0.5 * q * d / (rho_core * rho_core);
      v += 0.25 * q * q + slope * (rho - rho_core);
    }
  }
  return v;
}

Eigen::Vector2d PotentialField::repulsiveGradient(const Eigen::Vector2d& p) const {
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  for (const Obstacle& o : obstacles_) {
    const Eigen::Vector2d rel(p.x() - o.x, p.y() - o.y);
    const double dist = rel.norm();
    if (dist - o.radius >= params_.influence_distance || dist <= 0.0) continue;
    double dv, ddv;
    clearanceDerivatives(dist - o.radius, dv, ddv);
    g += dv * (rel / dist);
  }
  return g;
}

double PotentialField::minObstacleClearance(const Eigen::Vector2d& p) const {
  double m = std::numeric_limits<double>::infinity();
  for (const Obstacle& o : obstacles_) {
    const double rho = std::hypot(p.x() - o.x, p.y() - o.y) - o.radius;
    if (rho < m) m = rho;
  }
  return m;
}

Eigen::Vector2d PotentialField::mu(const Eigen::Vector2d& p, const TargetState& target, Eigen::Matrix2d* jac) const {
  Eigen::Vector2d f = Eigen::Vector2d::Zero();
  if (params_.gain <= 0.0) return f;
  const Eigen::Vector2d u = unitVector(target.heading), left(-u.y(), u.x());
  const double k = params_.gain, kt = params_.tangential_ratio;
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const Obstacle& o = obstacles_[i];
    const Eigen::Vector2d rel(p.x() - o.x, p.y() - o.y);
    const double dist = rel.norm();
    if (dist - o.radius >= params_.influence_distance) continue;
    const double s = sideFor(i, p, target);
    // At the exact centre the direction is undefined: push along the left normal of travel.
    const Eigen::Vector2d n = dist > 1e-12 ? Eigen::Vector2d(rel / dist) : left;
    double dv, ddv;
    clearanceDerivatives(dist - o.radius, dv, ddv);
    const double mag = -k * dv;  // >= 0, outward
    Eigen::Matrix2d m;           // I + s kt R, R = [[0, 1], [-1, 0]] (90 deg clockwise)
    m << 1.0, s * kt, -s * kt, 1.0;
    f += mag * (m * n);
    if (jac && dist > 1e-12) {
      const Eigen::Matrix2d nn = n * n.transpose();
      const Eigen::Matrix2d radial = (-k * ddv) * nn + (mag / dist) * (Eigen::Matrix2d::Identity() - nn);
      *jac += m * radial;
    }
  }
  return f;
}

Eigen::Vector2d PotentialField::repulsiveAcceleration(const Eigen::Vector2d& p, const TargetState& target) const {
  return mu(p, target, nullptr);
}

Eigen::Vector2d PotentialField::errorAccel(const ErrorState& s, const TargetState& tgt) const {
  Eigen::Vector2d a = -params_.alpha * s.e - params_.beta * s.ed;
  if (!obstacles_.empty()) a += mu(tgt.p + s.e, tgt, nullptr);
  return a;
}

PotentialField::ErrorState PotentialField::rk4(const ErrorState& s, double t, double h) const {
  const TargetState t0 = target_->at(t), tm = target_->at(t + 0.5 * h), t1 = target_->at(t + h);
  const Eigen::Vector2d k1v = s.ed, k1a = errorAccel(s, t0);
  ErrorState s2{s.e + 0.5 * h * k1v, s.ed + 0.5 * h * k1a};
  const Eigen::Vector2d k2v = s2.ed, k2a = errorAccel(s2, tm);
  ErrorState s3{s.e + 0.5 * h * k2v, s.ed + 0.5 * h * k2a};
  const Eigen::Vector2d k3v = s3.ed, k3a = errorAccel(s3, tm);
  ErrorState s4{s.e + h * k3v, s.ed + h * k3a};
  const Eigen::Vector2d k4v = s4.ed, k4a = errorAccel(s4, t1);
  ErrorState out;
  out.e = s.e + (h / 6.0) * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
  out.ed = s.ed + (h / 6.0) * (k1a + 2.0 * k2a + 2.0 * k3a + k4a);
  return out;
}

Reference PotentialField::evaluate(double t) {
  const double h = params_.step;
  if (t < 0.0) t = 0.0;  // (non-finite t never gets here: ReferenceSource::next refuses it)
  while (static_cast<double>(steps_ + 1) * h <= t + kGridSlack) {
    state_ = rk4(state_, static_cast<double>(steps_) * h, h);
    ++steps_;
    if (!obstacles_.empty()) {
      const TargetState tg = target_->at(static_cast<double>(steps_) * h);
      updateSides(tg.p + state_.e, tg);
    }
  }
  const double t_grid = static_cast<double>(steps_) * h;
  const double tau = t - t_grid;
  const ErrorState s = std::fabs(tau) > kGridSlack ? rk4(state_, t_grid, tau) : state_;

  const TargetState tgt = target_->at(t);
  Eigen::Matrix2d jac = Eigen::Matrix2d::Zero();
  const Eigen::Vector2d p = tgt.p + s.e, v = tgt.v + s.ed;
  Eigen::Vector2d edd = -params_.alpha * s.e - params_.beta * s.ed;
  if (!obstacles_.empty()) edd += mu(p, tgt, &jac);
  const Eigen::Vector2d a = tgt.a + edd;
  const Eigen::Vector2d eddd = -params_.alpha * s.ed - params_.beta * edd + jac * v;
  const Eigen::Vector2d j = tgt.j + eddd;
  out_p_ = p;
  out_v_ = v;
  out_a_ = a;

  Reference r;
  r.pose.x = p.x();
  r.pose.y = p.y();
  r.tool_down = tgt.tool_down;
  const double speed = v.norm();
  r.v = speed;
  const double hold_speed = params_.heading_hold_speed;
  const bool hold = speed < kStopSpeed || (speed < hold_speed && tgt.v.norm() < hold_speed);
  if (!hold) {
    const double v2 = speed * speed;
    r.pose.theta = std::atan2(v.y(), v.x());
    r.omega = (v.x() * a.y() - v.y() * a.x()) / v2;
    r.v_dot = v.dot(a) / speed;
    const double c_dot = v.x() * j.y() - v.y() * j.x();  // d/dt (x'y'' - y'x'')
    r.omega_dot = c_dot / v2 - 2.0 * r.omega * r.v_dot / speed;
    last_theta_ = r.pose.theta;
  } else {
    r.pose.theta = last_theta_;
    r.omega = 0.0;
    r.v_dot = a.dot(unitVector(last_theta_));
    r.omega_dot = 0.0;
  }
  return r;
}

}  // namespace core
}  // namespace sowing_robot
