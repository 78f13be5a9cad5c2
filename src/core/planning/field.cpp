#include "sowing_robot/core/planning/field.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/planning/speed_ramp.h"

namespace sowing_robot {
namespace core {

namespace {

/// Distance covered by a half-cosine speed ramp from v0 to v1 with peak |v_dot| = a [m].

/// Length of a cosine curvature ramp of height dk with peak |dkappa/ds| = rate [m].
double rampLength(double dk, double rate) { return 0.5 * M_PI * std::fabs(dk) / rate; }

/// Speed entering and leaving row i.
void rowSpeeds(const FieldParams& p, int i, double& v_in, double& v_out) {
  v_in = i == 0 ? (p.start_from_rest ? 0.0 : p.row_speed) : p.turn_speed;
  v_out = i == p.rows - 1 ? 0.0 : p.turn_speed;
}

}  // namespace

const ParamTable<FieldParams>& fieldTable() {
  using F = FieldParams;
  static const ParamTable<F> table = [] {
    ParamTable<F> t({
        integer("field/rows", &F::rows, 1, Limits::atLeast(1), "", "number of rows N"),
        number("field/row_length", &F::row_length, 100.0, Limits::positive(), "m", "length of each row"),
        number("field/row_spacing", &F::row_spacing, 1.0, Limits::positive(), "m",
               "distance between neighbouring rows"),
        number("field/start_x", &F::start_x, 0.0, Limits::any(), "m", "start of the first row, x"),
        number("field/start_y", &F::start_y, 3.0, Limits::any(), "m", "start of the first row, y"),
        number("field/heading", &F::heading, 0.0, Limits::any(), "rad",
               "direction of the first row; odd rows run back"),
        flag("field/rows_to_left", &F::rows_to_left, true, "the second row lies left of the first one's direction"),
        number("field/row_speed", &F::row_speed, 1.0, Limits::positive(), "m/s", "v_r on the rows"),
        number("field/turn_speed", &F::turn_speed, 0.5, Limits::positive(), "m/s",
               "speed on the headland turns (above potential/heading_hold_speed, up to field/row_speed)"),
        number(
            "field/min_turn_radius", &F::min_turn_radius, 0.5, Limits::positive(), "m",
            "the turns keep |curvature| <= 1/min_turn_radius; row_spacing below ~2 min_turn_radius gives bulb turns"),
        number("field/max_accel", &F::max_accel, 0.5, Limits::positive(), "m/s^2",
               "peak |v_dot| of the half-cosine speed ramps"),
        number("field/max_curvature_rate", &F::max_curvature_rate, 10.0, Limits::positive(), "1/m^2",
               "peak |dkappa/ds| in the turns (>= 1/(2 min_turn_radius^2))"),
        flag("field/start_from_rest", &F::start_from_rest, false,
             "true: the first row starts at rest and ramps up; false: at row_speed"),
        flag("field/approach", &F::approach, true,
             "with avoidance/plan_detours: the target starts at the robot's start pose and joins the first row "
             "within the detours' bounds; false: it starts at the row start"),
        number("field/approach_settle", &F::approach_settle, 1.0, Limits::nonNegative(), "m",
               "after the approach joins the row, the tool stays up for this distance while the robot settles "
               "on it (thesis field: with 0 the first seeds fall 8.6 mm off the row, with 1 m at most 3.4 mm)"),
        choice("field/follower", &F::follower, FieldFollower::kPotential,
               {{"potential", FieldFollower::kPotential}, {"path", FieldFollower::kPath}},
               "what follows the rows and turns: potential, the potential field (steers round obstacles also by "
               "repulsion); path, the path follower of input:=path on the field as a path (planned detours only, "
               "docs/interfaces.md)"),
    });
    t.nest("field/avoidance/", &F::avoidance, avoidanceTable());
    return t.nest("potential/", &F::potential, potentialFieldTable());
  }();
  return table;
}

FieldParams::FieldParams() { fieldTable().applyDefaults(*this); }

std::string FieldParams::validate() const {
  std::string e = firstError({fieldTable().checkRanges(*this), avoidance.validate()});
  if (!e.empty()) return e;
  if (start_pose && !allFinite(start_pose->x, start_pose->y, start_pose->theta)) return "start pose must be finite";
  if (!(run_out >= 0.0) || !std::isfinite(run_out))
    return "the tool's run-out past the last row's end = " + formatNumber(run_out) + " m must be finite and >= 0";
  if (turn_speed > row_speed)
    return "field/turn_speed = " + formatNumber(turn_speed) +
           " m/s must be <= field/row_speed = " + formatNumber(row_speed) + " m/s";
  if (turn_speed <= potential.heading_hold_speed)
    return "field/turn_speed = " + formatNumber(turn_speed) +
           " m/s must be above potential/heading_hold_speed = " + formatNumber(potential.heading_hold_speed) + " m/s";
  const double rate_min = 0.5 / (min_turn_radius * min_turn_radius);
  if (max_curvature_rate < rate_min)
    return "field/max_curvature_rate = " + formatNumber(max_curvature_rate) +
           " 1/m^2 must be >= 1/(2 field/min_turn_radius^2) = " + formatNumber(rate_min) + " 1/m^2";
  // Rows in between go turn_speed -> turn_speed and always fit; the first and last may have to slow down.
  for (const int i : {0, rows - 1}) {
    double v_in, v_out;
    rowSpeeds(*this, i, v_in, v_out);
    const double need = rampDistance(v_in, v_out, max_accel);
    if (v_in > v_out && row_length < need * (1.0 - 1e-12))
      return "field/row_length = " + formatNumber(row_length) + " m is too short to change speed from " +
             formatNumber(v_in) + " to " + formatNumber(v_out) + " m/s at max_accel (needs >= " + formatNumber(need) +
             " m)";
  }
  return "";
}

// ---------------------------------------------------------------------------------------------------
// HeadlandTurn

namespace {
// 5-point Gauss-Legendre on [0, 1].
constexpr double kGaussX[5] = {0.04691007703066800, 0.23076534494715845, 0.5, 0.76923465505284155, 0.95308992296933200};
constexpr double kGaussW[5] = {0.11846344252809454, 0.23931433524968324, 0.28444444444444444, 0.23931433524968324,
                               0.11846344252809454};
}  // namespace

void HeadlandTurn::segmentState(const Segment& g, double tau, double& theta, double& kappa, double& dkappa) {
  if (g.k0 == g.k1 || g.length <= 0.0) {
    kappa = g.k0;
    theta = g.theta0 + g.k0 * tau;
    dkappa = 0.0;
    return;
  }
  const double dk = g.k1 - g.k0, w = M_PI / g.length;
  double s, c;
  s = std::sin(w * tau);
  c = std::cos(w * tau);
  kappa = g.k0 + 0.5 * dk * (1.0 - c);
  theta = g.theta0 + g.k0 * tau + 0.5 * dk * (tau - s / w);
  dkappa = 0.5 * dk * w * s;
}

Eigen::Vector2d HeadlandTurn::integrate(const Segment& g, double a, double b) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  const double h = b - a;
  if (h == 0.0) return sum;
  for (int i = 0; i < 5; ++i) {
    double th, k, dk;
    segmentState(g, a + kGaussX[i] * h, th, k, dk);
    sum += kGaussW[i] * unitVector(th);
  }
  return h * sum;
}

bool HeadlandTurn::build(double k, double lambda, double away, double rate) {
  segments_.clear();
  nodes_.clear();
  const double ka = -lambda * k;
  // Curvature levels and holds; the hold at k is found from the total heading change pi.
  struct Piece {
    double k0, k1, length;
  };
  Piece pieces[7] = {{0.0, ka, rampLength(ka, rate)},   {ka, ka, away}, {ka, k, rampLength(k - ka, rate)}, {k, k, 0.0},
                     {k, ka, rampLength(k - ka, rate)}, {ka, ka, away}, {ka, 0.0, rampLength(ka, rate)}};
  double heading = 0.0;
  for (int i = 0; i < 7; ++i)
    if (i != 3) heading += 0.5 * (pieces[i].k0 + pieces[i].k1) * pieces[i].length;
  const double hold = (M_PI - heading) / k;
  if (hold < -1e-12 * std::max(1.0, 1.0 / k)) return false;
  pieces[3].length = std::max(0.0, hold);

  double s = 0.0, theta = 0.0;
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  peak_curvature_ = 0.0;
  for (const Piece& pc : pieces) {
    if (pc.length <= 0.0) continue;
    Segment g;
    g.s0 = s;
    g.length = pc.length;
    g.k0 = pc.k0;
    g.k1 = pc.k1;
    g.theta0 = theta;
    g.nodes = static_cast<int>(std::clamp(std::ceil(pc.length / 0.01), 16.0, 2000.0));
    g.node_step = pc.length / g.nodes;
    g.first_node = nodes_.size();
    for (int i = 0; i < g.nodes; ++i) {
      nodes_.push_back(p);
      p += integrate(g, i * g.node_step, i + 1 == g.nodes ? g.length : (i + 1) * g.node_step);
    }
    double kappa, dk;
    segmentState(g, g.length, theta, kappa, dk);
    peak_curvature_ = std::max({peak_curvature_, std::fabs(g.k0), std::fabs(g.k1)});
    segments_.push_back(g);
    s += pc.length;
  }
  length_ = s;
  end_ = p;
  bulb_ = lambda > 0.0;
  return true;
}

HeadlandTurn::HeadlandTurn(double width, double max_curvature, double rate) {
  if (!(width > 0.0 && max_curvature > 0.0 && rate > 0.0 && std::isfinite(width) && std::isfinite(max_curvature) &&
        std::isfinite(rate)))
    throw std::invalid_argument("HeadlandTurn: width, max_curvature and rate must be finite and > 0");
  const double k_hi = std::min(max_curvature, std::sqrt(2.0 * rate));
  auto widthAt = [&](double k, double lambda, double away) {
    if (!build(k, lambda, away, rate)) throw std::invalid_argument("HeadlandTurn: curvature ramps do not fit");
    return end_.y();
  };
  if (widthAt(k_hi, 0.0, 0.0) <= width) {
    // Rounded semicircle: the lateral offset falls as the curvature rises; bisect on kappa.
    double lo = std::min(k_hi, 1.0 / width), hi = k_hi;
    while (widthAt(lo, 0.0, 0.0) < width) lo *= 0.5;
    for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
      const double mid = 0.5 * (lo + hi);
      (widthAt(mid, 0.0, 0.0) > width ? lo : hi) = mid;
    }
    widthAt(0.5 * (lo + hi), 0.0, 0.0);
  } else {
    // Bulb turn at the largest curvature: b in [0, 1] grows the away lobe, b > 1 adds away arcs of
    // (b - 1) rad each. The lateral offset falls as b grows.
    auto widthB = [&](double b) { return b <= 1.0 ? widthAt(k_hi, b, 0.0) : widthAt(k_hi, 1.0, (b - 1.0) / k_hi); };
    double lo = 0.0, hi = 1.0;
    while (widthB(hi) > width) {
      lo = hi;
      hi += 0.25;
      if (hi > 1.0 + M_PI) throw std::invalid_argument("HeadlandTurn: no bulb turn found");
    }
    for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
      const double mid = 0.5 * (lo + hi);
      (widthB(mid) > width ? lo : hi) = mid;
    }
    widthB(0.5 * (lo + hi));
  }
  if (std::fabs(end_.y() - width) > 1e-9 * std::max(1.0, width) || std::fabs(end_.x()) > 1e-9 * std::max(1.0, width))
    throw std::invalid_argument("HeadlandTurn: turn construction did not converge");
}

void HeadlandTurn::evaluate(double s, Eigen::Vector2d& p, double& theta, double& kappa, double& dkappa) const {
  if (segments_.empty()) {
    p.setZero();
    theta = kappa = dkappa = 0.0;
    return;
  }
  s = std::clamp(s, 0.0, length_);
  std::size_t i = 0;
  while (i + 1 < segments_.size() && segments_[i + 1].s0 <= s) ++i;
  const Segment& g = segments_[i];
  const double tau = std::clamp(s - g.s0, 0.0, g.length);
  const int n = std::min(g.nodes - 1, static_cast<int>(tau / g.node_step));
  p = nodes_[g.first_node + n] + integrate(g, n * g.node_step, tau);
  segmentState(g, tau, theta, kappa, dkappa);
}

// ---------------------------------------------------------------------------------------------------
// FieldPath

Eigen::Vector2d FieldPath::rowStart(int i) const {
  const double h = params_.heading;
  const Eigen::Vector2d u = unitVector(h);
  const Eigen::Vector2d side = (params_.rows_to_left ? 1.0 : -1.0) * Eigen::Vector2d(-u.y(), u.x());
  Eigen::Vector2d p = Eigen::Vector2d(params_.start_x, params_.start_y) + (i * params_.row_spacing) * side;
  if (i % 2 == 1) p += params_.row_length * u;
  return p;
}

void FieldPath::addPhase(double distance, double v0, double v1) {
  Phase ph;
  ph.t0 = duration_;
  if (!phases_.empty()) {
    const Phase& b = phases_.back();
    ph.s0 = b.s0 + 0.5 * (b.v0 + b.v1) * b.duration;  // exact for cruises and half-cosine ramps
  }
  ph.v0 = v0;
  ph.v1 = v1;
  ph.duration = phaseDuration(distance, v0, v1, params_.max_accel);
  phases_.push_back(ph);
  duration_ += ph.duration;
}

FieldPath::FieldPath(const FieldParams& params, const std::vector<Obstacle>& obstacles) : params_(params) {
  const std::string e = params_.validate();
  if (!e.empty()) throw std::invalid_argument("FieldParams: " + e);
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const std::string oe = obstacles[i].validate();
    if (!oe.empty()) throw std::invalid_argument("obstacles[" + std::to_string(i) + "]: " + oe);
  }
  const bool plan = params_.avoidance.plan_detours && !obstacles.empty();
  int n = params_.rows;
  if (n > 1) turn_ = HeadlandTurn(params_.row_spacing, 1.0 / params_.min_turn_radius, params_.max_curvature_rate);

  // Geometry. With a plan, the seed drill's tool point (run_out behind the axle) must reach each row's end while the
  // robot is still on the row's line: every row is driven on by run_out past its end before its turn, so the turn,
  // which ends at the same along-row position, leaves the next row run_out before its start (a straight lead-in).
  // The thesis path (no plan) keeps the thesis's rows.
  const double ext = params_.avoidance.plan_detours ? params_.run_out : 0.0;
  double s = 0.0;
  bool cut = false;
  for (int i = 0; i < n; ++i) {
    const double h = params_.heading + (i % 2 == 1 ? M_PI : 0.0);
    Element row;
    row.s0 = s;
    row.length = params_.row_length;
    row.p0 = rowStart(i);
    row.heading = h;
    if (i > 0) {  // the lead-in left by the previous row's run-out; the tool is asked for from the row's start
      row.along0 = -ext;
      row.length += ext;
    }
    if (plan) {
      const RowPlan rp = planRow(i, row.p0, h, params_.row_length, params_.row_speed, obstacles, params_.avoidance,
                                 params_.potential.influence_distance, status_);
      row.detour_first = detours_.size();
      row.detour_count = rp.detours.size();
      detours_.insert(detours_.end(), rp.detours.begin(), rp.detours.end());
      if (rp.cut) {  // the path ends here, at rest
        row.length = rp.stop - row.along0;
        n = i + 1;
        cut = true;
      }
    }
    if (!cut) row.length += ext;  // the tool point reaches the row's end on its line
    if (i == 0 && params_.approach && params_.avoidance.plan_detours && params_.start_pose) {
      planApproach(row, n == 1 ? 0.0 : params_.turn_speed, obstacles);
      if (has_approach_) {
        Element ap;
        ap.length = approach_.curve.length();
        ap.approach = true;
        ap.p0 = row.p0;
        ap.heading = h;
        elements_.push_back(ap);
        s = ap.length;
        row.s0 = s;
        // The approach joins the row before its start (approachLead()), so the robot has settled and the tool is
        // down when the tool point reaches the row's start.
        row.along0 = approach_.curve.joinAlong() - approachLead();
        row.tool_from = row.along0 + params_.approach_settle;
        row.length -= row.along0;
      }
    }
    elements_.push_back(row);
    s += row.length;
    if (i + 1 < n) {
      Element t;
      t.s0 = s;
      t.length = turn_.length();
      t.turn = true;
      t.p0 = row.p0 + (params_.row_length + ext) * unitVector(h);
      t.heading = h;
      t.side = (params_.rows_to_left ? 1.0 : -1.0) * (i % 2 == 0 ? 1.0 : -1.0);
      elements_.push_back(t);
      s += t.length;
    }
  }
  total_length_ = s;

  // Speed profile along the same sequence.
  const double vt = params_.turn_speed;
  std::size_t k = has_approach_ ? 1 : 0;
  for (int i = 0; i < n; ++i) {
    const double v_in = i == 0 ? (params_.start_from_rest ? 0.0 : params_.row_speed) : vt;
    const double v_out = i == n - 1 ? 0.0 : vt;
    const Element& row = elements_[k];
    if (i == 0 && has_approach_)
      addRowPhases(row.length, v_in, v_out, row, elements_[0].length, approach_.speed);
    else
      addRowPhases(row.length, v_in, v_out, row);
    k += 2;
    if (i + 1 < n) addPhase(turn_.length(), vt, vt);
  }
}

double FieldPath::approachLead() const {
  return params_.avoidance.plan_detours ? params_.approach_settle + params_.run_out : 0.0;
}

void FieldPath::planApproach(const Element& row, double v_out, const std::vector<Obstacle>& obstacles) {
  const AvoidanceParams& av = params_.avoidance;
  const double vr = params_.row_speed, a = params_.max_accel, keep = 1.0 - av.tracking_reserve;
  // A start on the row's start needs no approach (the tool point, behind it on the line, reaches the row on it).
  approach_ = core::planApproach(row.p0, row.heading, *params_.start_pose, ApproachLimits(), {});
  if (!approach_.needed) {
    has_approach_ = false;
    return;
  }
  // Otherwise the approach is planned onto the row's line extended back by approachLead(): it joins there at the
  // earliest, approach_settle plus the tool's run-out before the row's start.
  const double lead = approachLead();
  const Eigen::Vector2d p0 = row.p0 - lead * unitVector(row.heading);
  ApproachLimits lim;
  lim.max_curvature = av.max_curvature;
  lim.max_curvature_rate = params_.max_curvature_rate;
  lim.max_yaw_rate = keep * av.max_yaw_rate;
  lim.max_lateral_accel = keep * av.max_lateral_accel;
  lim.row_speed = vr;
  lim.clearance = av.pathClearance(params_.potential.influence_distance);
  // Join where the row speed can still drop to the first detour's speed, or to the row end's.
  lim.join_limit = lead + row.along0 + row.length - rampDistance(vr, v_out, a);
  if (row.detour_count > 0) {
    const Detour& d = detours_[row.detour_first];
    lim.join_limit = std::min(lim.join_limit, lead + d.begin - rampDistance(vr, d.speed, a));
  }
  approach_ = core::planApproach(p0, row.heading, *params_.start_pose, lim, obstacles);
  has_approach_ = approach_.needed && approach_.ok;
  if (approach_.needed && !approach_.ok) {
    status_.within_bounds = false;
    if (status_.bounds_note.empty())
      status_.bounds_note =
          "no approach from the start pose (" + approach_.why + "): the target starts at the row start";
  }
}

void FieldPath::addRowPhases(double L, double v_in, double v_out, const Element& row, double lead, double lead_speed) {
  const double a = params_.max_accel, vr = params_.row_speed;
  // Knots: the row start, each detour's speed window [begin, end], the row end; each with its speed.
  // With an approach of length `lead` first, positions count from the path start: the approach is a
  // window at lead_speed after the ramp from v_in, and the row's positions move by lead - along0.
  struct Knot {
    double b, e, w;
  };
  std::vector<Knot> knots{{0.0, 0.0, v_in}};
  if (lead > 0.0)
    knots.push_back({v_in < lead_speed ? std::min(lead, rampDistance(v_in, lead_speed, a)) : 0.0, lead, lead_speed});
  const double shift = lead - row.along0;
  for (std::size_t d = row.detour_first; d < row.detour_first + row.detour_count; ++d)
    knots.push_back({detours_[d].begin + shift, detours_[d].end() + shift, detours_[d].speed});
  L += lead;
  knots.push_back({L, L, v_out});
  const std::size_t m = knots.size();
  auto reach = [&](double w, double gap) { return std::sqrt(w * w + 4.0 * a * std::max(0.0, gap) / M_PI); };
  if (m > 2) {
    // Backward: each window slow enough to brake for the next; forward: no faster than it can speed up
    // to. The row start and end speeds are fixed; where they cannot be met, the bounds do not hold.
    for (std::size_t j = m - 2; j >= 1; --j)
      knots[j].w = std::min(knots[j].w, reach(knots[j + 1].w, knots[j + 1].b - knots[j].e));
    for (std::size_t j = 0; j + 1 < m; ++j) {
      const double gap = knots[j + 1].b - knots[j].e;
      if (j + 1 < m - 1) knots[j + 1].w = std::min(knots[j + 1].w, reach(knots[j].w, gap));
      if (knots[j].w > reach(knots[j + 1].w, gap) * (1.0 + 1e-12) && j + 1 < m - 1) {
        knots[j + 1].w = std::sqrt(std::max(0.0, knots[j].w * knots[j].w - 4.0 * a * gap / M_PI));
        status_.within_bounds = false;
        if (status_.bounds_note.empty())
          status_.bounds_note = "row speed cannot drop to a detour's speed in time (detour too close to the row start)";
      }
    }
  }
  for (std::size_t j = 0; j + 1 < m; ++j) {
    const double wa = knots[j].w, wb = knots[j + 1].w;
    const double gap = knots[j + 1].b - knots[j].e;
    const double vp = std::max({std::min(vr, std::sqrt(0.5 * (4.0 * a * gap / M_PI + wa * wa + wb * wb))), wa, wb});
    const double d1 = vp > wa ? rampDistance(wa, vp, a) : 0.0;
    const double d2 = vp > wb ? rampDistance(vp, wb, a) : 0.0;
    if (d1 > 0.0) addPhase(d1, wa, vp);
    const double cruise = gap - d1 - d2;
    if (cruise > 1e-12 * gap) addPhase(cruise, vp, vp);
    if (d2 > 0.0) addPhase(d2, vp, wb);
    if (j + 2 < m && knots[j + 1].e > knots[j + 1].b) addPhase(knots[j + 1].e - knots[j + 1].b, wb, wb);
  }
}

void FieldPath::arcLength(double t, double& s, double& sd, double& sdd, double& sddd) const {
  sd = sdd = sddd = 0.0;
  if (!(t > 0.0)) t = 0.0;
  if (t >= duration_ || phases_.empty()) {
    s = total_length_;
    if (phases_.empty()) s = 0.0;
    return;
  }
  auto it = std::upper_bound(phases_.begin(), phases_.end(), t, [](double v, const Phase& p) { return v < p.t0; });
  const Phase& ph = *(it == phases_.begin() ? it : it - 1);
  const RampState r = rampState(ph.s0, ph.v0, ph.v1, ph.duration, t - ph.t0);
  s = r.s;
  sd = r.sd;
  sdd = r.sdd;
  sddd = r.sddd;
}

TargetState FieldPath::at(double t) const {
  double s, sd, sdd, sddd;
  arcLength(t, s, sd, sdd, sddd);
  s = std::clamp(s, 0.0, total_length_);
  auto it =
      std::upper_bound(elements_.begin(), elements_.end(), s, [](double v, const Element& e) { return v < e.s0; });
  const Element& el = *(it == elements_.begin() ? it : it - 1);
  const double sigma = std::clamp(s - el.s0, 0.0, el.length) + el.along0;

  Eigen::Vector2d p;
  double theta, kappa = 0.0, dkappa = 0.0;
  if (el.approach) {
    approach_.curve.evaluate(sigma, p, theta, kappa, dkappa);
  } else if (el.turn) {
    Eigen::Vector2d local;
    double th_l, k_l, dk_l;
    turn_.evaluate(sigma, local, th_l, k_l, dk_l);
    double sn, c;
    sn = std::sin(el.heading);
    c = std::cos(el.heading);
    const double ly = el.side * local.y();
    p = el.p0 + Eigen::Vector2d(c * local.x() - sn * ly, sn * local.x() + c * ly);
    theta = el.heading + el.side * th_l;
    kappa = el.side * k_l;
    dkappa = el.side * dk_l;
  } else {
    for (std::size_t d = el.detour_first; d < el.detour_first + el.detour_count; ++d) {
      const Detour& dt = detours_[d];
      if (sigma <= dt.begin || sigma >= dt.end()) continue;
      // On a detour: p = p0 + sigma u + y(sigma) n with sigma' = sd (along-row speed).
      double y, y1, y2, y3;
      dt.lateral(sigma, y, y1, y2, y3);
      const Eigen::Vector2d u = unitVector(el.heading), nl(-u.y(), u.x());
      const Eigen::Vector2d tang = u + y1 * nl;
      TargetState out;
      out.p = el.p0 + sigma * u + y * nl;
      out.v = sd * tang;
      out.a = sdd * tang + (sd * sd * y2) * nl;
      out.j = sddd * tang + (3.0 * sd * sdd * y2) * nl + (sd * sd * sd * y3) * nl;
      out.heading = wrapAngle(el.heading + std::atan(y1));
      out.tool_down = t < duration_ && sigma >= el.tool_from;
      return out;
    }
    p = el.p0 + sigma * unitVector(el.heading);
    theta = el.heading;
  }
  const Eigen::Vector2d T = unitVector(theta), N(-T.y(), T.x());
  TargetState out;
  out.p = p;
  out.v = sd * T;
  out.a = sdd * T + (sd * sd * kappa) * N;
  out.j = sddd * T + (3.0 * sd * sdd * kappa) * N + (sd * sd * sd) * (dkappa * N - kappa * kappa * T);
  out.heading = wrapAngle(theta);
  out.tool_down = !el.turn && !el.approach && t < duration_ && sigma >= el.tool_from;
  return out;
}

bool FieldPath::onTurn(double t) const {
  double s, sd, sdd, sddd;
  arcLength(t, s, sd, sdd, sddd);
  auto it =
      std::upper_bound(elements_.begin(), elements_.end(), s, [](double v, const Element& e) { return v < e.s0; });
  return (it == elements_.begin() ? it : it - 1)->turn && t < duration_;
}

// ---------------------------------------------------------------------------------------------------
// FieldReference

namespace {
std::unique_ptr<FieldPath> makePath(const FieldParams& p, const std::vector<Obstacle>& obstacles) {
  return std::make_unique<FieldPath>(p, obstacles);
}
/// What the repulsion sees: the raw obstacles (thesis), or, with a plan, the ones shrunk to the plan.
std::vector<Obstacle> fieldObstacles(const FieldParams& p, const std::vector<Obstacle>& obstacles) {
  if (!p.avoidance.plan_detours) return obstacles;
  return repulsionObstacles(obstacles, p.avoidance, p.potential.influence_distance);
}
}  // namespace

FieldReference::FieldReference(const FieldParams& params, std::vector<Obstacle> obstacles)
    : params_(params),
      obstacles_(std::move(obstacles)),
      field_(params.potential, makePath(params, obstacles_), fieldObstacles(params, obstacles_)),
      duration_(path().duration()),
      status_(path().status()) {}

void FieldReference::setObstacles(std::vector<Obstacle> obstacles) {
  if (!params_.avoidance.plan_detours) {
    field_.setObstacles(obstacles);
    obstacles_ = std::move(obstacles);
    return;
  }
  std::unique_ptr<FieldPath> path = makePath(params_, obstacles);  // throws before anything changes
  std::vector<Obstacle> repulsion = fieldObstacles(params_, obstacles);
  const double t = field_.gridTime();
  const TargetState before = field_.target().at(t), after = path->at(t);
  AvoidanceStatus status = path->status();
  const double moved = std::max((before.p - after.p).norm(), (before.v - after.v).norm());
  if (moved > 1e-9 && status.within_bounds) {
    char b[200];
    std::snprintf(b, sizeof(b),
                  "the obstacles changed at t = %.3f s too close ahead to plan for: the plan moved %.3f m (or m/s) "
                  "at once, and the reference is pulled onto it",
                  t, moved);
    status.within_bounds = false;
    status.bounds_note = b;
  }
  field_.setObstacles(std::move(repulsion));
  field_.setTarget(std::move(path));
  obstacles_ = std::move(obstacles);
  duration_ = this->path().duration();
  status_ = status;
}

std::unique_ptr<ReferenceSource> FieldReference::clone() const {
  auto c = std::make_unique<FieldReference>(*this);
  c->reset();
  return c;
}

}  // namespace core
}  // namespace sowing_robot
