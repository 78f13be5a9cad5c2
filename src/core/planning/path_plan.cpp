#include "sowing_robot/core/planning/path_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sowing_robot/core/planning/speed_ramp.h"

namespace sowing_robot {
namespace core {

const ParamTable<PathParams>& pathTable() {
  using P = PathParams;
  static const ParamTable<P> table({
      number("path/v_max", &P::v_max, 1.0, Limits::above(0.0, 10.0), "m/s", "speed on the straights"),
      number("path/a_max", &P::a_max, 0.5, Limits::positive(), "m/s^2", "peak |v_dot| of the half-cosine speed ramps"),
      number("path/lateral_accel", &P::lateral_accel, 0.5, Limits::positive(), "m/s^2",
             "speed limit on the rounded corners: v^2 * peak curvature <= this"),
      number("path/max_curvature", &P::max_curvature, 4.0, Limits::positive(), "1/m",
             "peak curvature of a rounded corner; a corner whose rounding does not fit between its neighbours "
             "within it is turned in place"),
      number("path/turn_rate", &P::turn_rate, 1.0, Limits::positive(), "rad/s", "peak yaw rate turning in place"),
      number("path/turn_accel", &P::turn_accel, 1.0, Limits::positive(), "rad/s^2",
             "peak yaw acceleration turning in place"),
      number("path/simplify_tolerance", &P::simplify_tolerance, 0.02, Limits::nonNegative(), "m",
             "points closer than this to the line through their neighbours are dropped (Douglas-Peucker), so a "
             "planner's grid steps do not become corners; 0: every point kept"),
      number("path/goal_tolerance", &P::goal_tolerance, 0.05, Limits::positive(), "m",
             "the goal is reached once the robot stops within this distance of the last point"),
      flag("path/tool_down", &P::tool_down, false,
           "the tool is down (seeds fall) along the path, up while turning in place; false: a transit"),
  });
  return table;
}

PathParams::PathParams() { pathTable().applyDefaults(*this); }

std::string PathParams::validate() const { return pathTable().checkRanges(*this); }

namespace {

constexpr double kSamePoint = 1e-3;      // [m] points closer than this are one
constexpr double kStraightAngle = 1e-6;  // [rad] a smaller change of direction is no corner
constexpr double kMaxFilletAngle = 3.0;  // [rad] a sharper corner (near a reversal) is always turned in place

double headingOf(const Eigen::Vector2d& d) { return std::atan2(d.y(), d.x()); }

/// Heading of a cosine-bump fillet (turn phi over length len) at sigma, from theta0.
double filletHeading(double theta0, double phi, double len, double sigma) {
  const double x = sigma / len;
  return theta0 + phi * (x - std::sin(2.0 * M_PI * x) / (2.0 * M_PI));
}

/// int_a^b (cos, sin)(heading) d sigma by 3-point Gauss-Legendre (the heading is smooth over one node step).
Eigen::Vector2d filletChord(double theta0, double phi, double len, double a, double b) {
  static const double kX[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)};
  static const double kW[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int i = 0; i < 3; ++i) sum += kW[i] * unitVector(filletHeading(theta0, phi, len, mid + half * kX[i]));
  return half * sum;
}

/// End point of a unit-length fillet turning |phi| from heading 0 at the origin.
Eigen::Vector2d unitFilletEnd(double phi, int nodes) {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  for (int i = 0; i < nodes; ++i) p += filletChord(0.0, phi, 1.0, double(i) / nodes, double(i + 1) / nodes);
  return p;
}

void simplifyRange(const std::vector<Eigen::Vector2d>& pts, std::size_t i, std::size_t j, double tol,
                   std::vector<bool>& keep) {
  if (j <= i + 1) return;
  double worst = -1.0;
  std::size_t at = i;
  for (std::size_t k = i + 1; k < j; ++k) {
    const double u = segmentParameter(pts[k], pts[i], pts[j]);
    const double dist = (pts[k] - (pts[i] + u * (pts[j] - pts[i]))).norm();
    if (dist > worst) worst = dist, at = k;
  }
  if (worst <= tol) return;
  keep[at] = true;
  simplifyRange(pts, i, at, tol, keep);
  simplifyRange(pts, at, j, tol, keep);
}

}  // namespace

std::vector<Eigen::Vector2d> simplifyPolyline(const std::vector<Eigen::Vector2d>& points, double tolerance) {
  std::vector<Eigen::Vector2d> unique;
  for (const Eigen::Vector2d& p : points)
    if (unique.empty() || (p - unique.back()).norm() >= kSamePoint) unique.push_back(p);
  if (unique.size() < 3 || !(tolerance > 0.0)) return unique;
  std::vector<bool> keep(unique.size(), false);
  keep.front() = keep.back() = true;
  simplifyRange(unique, 0, unique.size() - 1, tolerance, keep);
  std::vector<Eigen::Vector2d> out;
  for (std::size_t k = 0; k < unique.size(); ++k)
    if (keep[k]) out.push_back(unique[k]);
  return out;
}

namespace {
/// simplifyPolyline of each run of equal tool flags (so a point where the tool goes up or down stays); tool[k] is
/// the flag of the segment from points[k] on, for the kept points as for the given ones.
std::vector<Eigen::Vector2d> simplifyRuns(const std::vector<Eigen::Vector2d>& points, double tolerance,
                                          std::vector<bool>& tool) {
  std::vector<Eigen::Vector2d> out;
  std::vector<bool> flags;
  std::size_t a = 0;
  while (a + 1 < points.size()) {
    std::size_t b = a + 1;
    while (b + 1 < points.size() && tool[b] == tool[a]) ++b;
    const std::vector<Eigen::Vector2d> run =
        simplifyPolyline(std::vector<Eigen::Vector2d>(points.begin() + a, points.begin() + b + 1), tolerance);
    for (std::size_t k = 0; k + 1 < run.size(); ++k) {
      if (!out.empty() && (run[k] - out.back()).norm() < kSamePoint) continue;
      out.push_back(run[k]);
      flags.push_back(tool[a]);
    }
    a = b;
  }
  if (out.empty() || (points.back() - out.back()).norm() >= kSamePoint) {
    out.push_back(points.back());
    flags.push_back(false);
  }
  tool = std::move(flags);
  return out;
}
}  // namespace

PathPlan::PathPlan(const std::vector<Eigen::Vector2d>& points, const PathStart& start, const PathParams& params,
                   std::vector<bool> tool)
    : params_(params) {
  const std::string e = params_.validate();
  if (!e.empty()) throw std::invalid_argument("path parameters: " + e);
  if (!allFinite(start.pose.x, start.pose.y, start.pose.theta, start.v) || start.v < 0.0)
    throw std::invalid_argument("path start: a non-finite pose or a negative speed");
  if (points.empty()) throw std::invalid_argument("path: no point");
  if (!tool.empty() && tool.size() + 1 != points.size())
    throw std::invalid_argument("path: " + std::to_string(tool.size()) + " tool flags for " +
                                std::to_string(points.size()) + " points (one per segment)");
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!points[k].allFinite()) throw std::invalid_argument("path: point " + std::to_string(k) + " is not finite");

  // Join: a lead along the current heading long enough to stop from the current speed (twice that, so half of
  // it is left beside a rounded corner at its end), then the path from the point closest to the lead's end.
  // Without flags the tool is params_.tool_down everywhere (the lead too); with them it is up on the lead.
  const bool flagged = !tool.empty();
  if (!flagged) tool.assign(points.size() - 1, params_.tool_down);
  const std::vector<Eigen::Vector2d> path = flagged ? simplifyRuns(points, params_.simplify_tolerance, tool)
                                                    : simplifyPolyline(points, params_.simplify_tolerance);
  const bool lead_tool = !flagged && params_.tool_down;
  const Eigen::Vector2d p0(start.pose.x, start.pose.y);
  std::vector<Eigen::Vector2d> v{p0};
  std::vector<bool> v_tool{lead_tool};  // the flag of the segment from each vertex on
  Eigen::Vector2d from = p0;
  if (start.v > 0.0) {
    from = p0 + (2.0 * rampDistance(start.v, 0.0, params_.a_max) + 0.01) * unitVector(start.pose.theta);
    v.push_back(from);
    v_tool.push_back(lead_tool);
  }
  std::size_t seg = 0;
  Eigen::Vector2d join = path.front();
  double best = (from - join).norm();
  for (std::size_t k = 0; k + 1 < path.size(); ++k) {
    const Eigen::Vector2d q = path[k] + segmentParameter(from, path[k], path[k + 1]) * (path[k + 1] - path[k]);
    if ((from - q).norm() < best - 1e-12) best = (from - q).norm(), join = q, seg = k;
  }
  v.push_back(join);
  v_tool.push_back(path.size() > 1 ? tool[seg] : false);
  for (std::size_t k = seg + 1; k < path.size(); ++k) {
    v.push_back(path[k]);
    v_tool.push_back(k + 1 < path.size() ? tool[k] : false);
  }
  std::vector<bool> vertex_tool;
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (vertices_.empty() || (v[k] - vertices_.back()).norm() >= kSamePoint) {
      vertices_.push_back(v[k]);
      vertex_tool.push_back(v_tool[k]);
    } else {
      vertex_tool.back() = v_tool[k];  // the segment from the kept vertex is now the dropped one's
    }
  }

  end_theta_ = start.pose.theta;
  const std::size_t n = vertices_.size();
  if (n < 2) return;  // already there: the plan is the end hold
  // Corners: a fillet where its tangent length fits in half of each neighbouring segment, else a pivot.
  std::vector<double> seg_len(n - 1), seg_dir(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    seg_len[k] = (vertices_[k + 1] - vertices_[k]).norm();
    seg_dir[k] = headingOf(vertices_[k + 1] - vertices_[k]);
  }
  std::vector<double> turn(n, 0.0), tangent(n, 0.0), fillet_len(n, 0.0);
  std::vector<bool> pivot(n, false);
  turn[0] = wrapAngle(seg_dir[0] - start.pose.theta);
  pivot[0] = std::fabs(turn[0]) > kStraightAngle;  // start.v > 0: the lead keeps the heading, turn[0] ~ 0
  for (std::size_t k = 1; k + 1 < n; ++k) {
    const double phi = wrapAngle(seg_dir[k] - seg_dir[k - 1]);
    turn[k] = phi;
    if (std::fabs(phi) <= kStraightAngle) continue;
    const double len = 2.0 * std::fabs(phi) / params_.max_curvature;
    const double t = std::fabs(phi) <= kMaxFilletAngle
                         ? len * std::fabs(unitFilletEnd(std::fabs(phi), kFilletNodes).y()) / std::sin(std::fabs(phi))
                         : std::numeric_limits<double>::infinity();
    if (t <= 0.5 * std::min(seg_len[k - 1], seg_len[k])) {
      tangent[k] = t;
      fillet_len[k] = len;
    } else {
      pivot[k] = true;
    }
  }
  // Elements, and the turn in place after each (0: none): the robot is at rest there.
  std::vector<double> pivot_after;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const bool corner = k + 1 < n - 1;
    addStraight(vertices_[k] + tangent[k] * unitVector(seg_dir[k]), seg_len[k] - tangent[k] - tangent[k + 1],
                seg_dir[k], vertex_tool[k]);
    pivot_after.push_back(corner && pivot[k + 1] ? turn[k + 1] : 0.0);
    if (corner && fillet_len[k + 1] > 0.0) {
      addFillet(vertices_[k + 1], tangent[k + 1], seg_dir[k], turn[k + 1], fillet_len[k + 1],
                vertex_tool[k] && vertex_tool[k + 1]);
      pivot_after.push_back(0.0);
    }
  }
  end_theta_ = seg_dir[n - 2];
  if (pivot[0]) addPivot(start.pose.theta, turn[0]);
  planSpeeds(start.v, pivot_after);
}

void PathPlan::addStraight(const Eigen::Vector2d& from, double length, double heading, bool tool_down) {
  Element el;
  el.tool_down = tool_down;
  el.s0 = length_;
  el.length = std::max(0.0, length);
  el.p0 = from;
  el.theta0 = heading;
  el.v_limit = params_.v_max;
  length_ += el.length;
  elements_.push_back(el);
}

void PathPlan::addFillet(const Eigen::Vector2d& vertex, double tangent, double theta0, double phi, double length,
                         bool tool_down) {
  Element el;
  el.tool_down = tool_down;
  el.s0 = length_;
  el.length = length;
  el.p0 = vertex - tangent * unitVector(theta0);
  el.theta0 = theta0;
  el.phi = phi;
  el.v_limit = std::min(params_.v_max, std::sqrt(params_.lateral_accel * length / (2.0 * std::fabs(phi))));
  el.nodes.reserve(kFilletNodes + 1);
  el.nodes.push_back(el.p0);
  for (int i = 0; i < kFilletNodes; ++i)
    el.nodes.push_back(el.nodes.back() +
                       filletChord(theta0, phi, length, length * i / kFilletNodes, length * (i + 1) / kFilletNodes));
  max_cut_ = std::max(max_cut_, (el.nodes[kFilletNodes / 2] - vertex).norm());  // closest to the vertex at its middle
  length_ += el.length;
  ++fillets_;
  elements_.push_back(el);
}

void PathPlan::planSpeeds(double v_start, const std::vector<double>& pivot_after) {
  // Node j lies between elements j-1 and j. A half-cosine ramp covers (v1^2 - v0^2)/(2 a_e) with a_e = 2 a/pi.
  const std::size_t m = elements_.size();
  const double a_e = 2.0 * params_.a_max / M_PI;
  std::vector<double> v(m + 1, 0.0);
  v[0] = v_start;
  for (std::size_t j = 1; j < m; ++j)
    v[j] = pivot_after[j - 1] != 0.0 ? 0.0 : std::min(elements_[j - 1].v_limit, elements_[j].v_limit);
  auto reach = [&](double from, std::size_t j) {  // the fastest the far end of element j can be
    const Element& el = elements_[j];
    return el.phi != 0.0 ? from : std::sqrt(from * from + 2.0 * a_e * el.length);
  };
  for (std::size_t j = 0; j < m; ++j) v[j + 1] = std::min(v[j + 1], reach(v[j], j));
  for (std::size_t j = m; j-- > 1;) v[j] = std::min(v[j], reach(v[j + 1], j));
  for (std::size_t j = 0; j < m; ++j) {
    const Element& el = elements_[j];
    const double v0 = v[j], v1 = v[j + 1];
    if (el.phi != 0.0) {
      addMove(el.length, v0, v0);
    } else if (el.length > 0.0) {
      double peak = std::min(el.v_limit, std::sqrt((2.0 * a_e * el.length + v0 * v0 + v1 * v1) / 2.0));
      peak = std::max({peak, v0, v1});
      const double up = rampDistance(v0, peak, params_.a_max), down = rampDistance(peak, v1, params_.a_max);
      const double cruise = el.length - up - down;
      if (up > 0.0) addMove(up, v0, peak);
      if (cruise > 1e-12 * el.length && peak > 0.0) addMove(cruise, peak, peak);
      if (down > 0.0) addMove(down, peak, v1);
    }
    if (pivot_after[j] != 0.0) addPivot(el.theta0, pivot_after[j]);  // pivots follow straights
  }
}

void PathPlan::addMove(double distance, double v0, double v1) {
  Phase ph;
  ph.t0 = duration_;
  ph.s0 = phases_.empty() ? 0.0 : phases_.back().s0 + phases_.back().distance;
  ph.distance = distance;
  ph.v0 = v0;
  ph.v1 = v1;
  ph.duration = phaseDuration(distance, v0, v1, params_.a_max);
  duration_ += ph.duration;
  phases_.push_back(ph);
}

void PathPlan::addPivot(double theta0, double dtheta) {
  Phase ph;
  ph.t0 = duration_;
  ph.s0 = phases_.empty() ? 0.0 : phases_.back().s0 + phases_.back().distance;
  ph.pivot = true;
  ph.theta0 = theta0;
  ph.dtheta = dtheta;
  // Cosine-bump yaw rate: peak 2 |dtheta| / T, peak yaw acceleration 2 pi |dtheta| / T^2.
  const double a = std::fabs(dtheta);
  ph.duration = std::max(2.0 * a / params_.turn_rate, std::sqrt(2.0 * M_PI * a / params_.turn_accel));
  duration_ += ph.duration;
  ++pivots_;
  phases_.push_back(ph);
}

const PathPlan::Phase& PathPlan::phaseAt(double tau) const {
  auto it = std::upper_bound(phases_.begin(), phases_.end(), tau, [](double x, const Phase& p) { return x < p.t0; });
  return *(it == phases_.begin() ? it : it - 1);
}

const PathPlan::Element& PathPlan::elementAt(double s) const {
  auto it =
      std::upper_bound(elements_.begin(), elements_.end(), s, [](double x, const Element& e) { return x < e.s0; });
  return *(it == elements_.begin() ? it : it - 1);
}

void PathPlan::geometry(double s, Eigen::Vector2d& p, double& theta, double& kappa, double& dkappa) const {
  const Element& el = elementAt(s);
  const double sigma = std::clamp(s - el.s0, 0.0, el.length);
  kappa = dkappa = 0.0;
  if (el.phi == 0.0) {
    p = el.p0 + sigma * unitVector(el.theta0);
    theta = el.theta0;
    return;
  }
  const double x = sigma / el.length, w = 2.0 * M_PI / el.length;
  const int i = std::min(kFilletNodes - 1, static_cast<int>(x * kFilletNodes));
  p = el.nodes[i] + filletChord(el.theta0, el.phi, el.length, el.length * i / kFilletNodes, sigma);
  theta = filletHeading(el.theta0, el.phi, el.length, sigma);
  kappa = el.phi / el.length * (1.0 - std::cos(w * sigma));
  dkappa = el.phi / el.length * w * std::sin(w * sigma);
}

Eigen::Vector2d PathPlan::goal() const { return vertices_.empty() ? Eigen::Vector2d::Zero() : vertices_.back(); }

Reference PathPlan::at(double tau) const {
  Reference r;
  r.tool_down = false;
  if (!(tau > 0.0)) tau = 0.0;
  if (phases_.empty() || tau >= duration_) {
    const Eigen::Vector2d g = goal();
    r.pose = Pose2D{g.x(), g.y(), end_theta_};
    r.stop = true;
    return r;
  }
  const Phase& ph = phaseAt(tau);
  const double t = tau - ph.t0;
  Eigen::Vector2d p;
  double theta, kappa, dkappa;
  if (ph.pivot) {
    geometry(ph.s0, p, theta, kappa, dkappa);
    const double x = t / ph.duration, w = 2.0 * M_PI / ph.duration;
    r.pose = Pose2D{p.x(), p.y(), wrapAngle(ph.theta0 + ph.dtheta * (x - std::sin(w * t) / (2.0 * M_PI)))};
    r.omega = ph.dtheta / ph.duration * (1.0 - std::cos(w * t));
    r.omega_dot = ph.dtheta / ph.duration * w * std::sin(w * t);
    return r;
  }
  const RampState m = rampState(ph.s0, ph.v0, ph.v1, ph.duration, t);
  const double s = std::min(m.s, ph.s0 + ph.distance);
  geometry(s, p, theta, kappa, dkappa);
  r.pose = Pose2D{p.x(), p.y(), wrapAngle(theta)};
  r.v = m.sd;
  r.omega = kappa * m.sd;
  r.v_dot = m.sdd;
  r.omega_dot = dkappa * m.sd * m.sd + kappa * m.sdd;
  r.tool_down = elementAt(s).tool_down;
  return r;
}

double PathPlan::arcLengthAt(double tau) const {
  if (phases_.empty() || tau >= duration_) return length_;
  if (!(tau > 0.0)) return 0.0;
  const Phase& ph = phaseAt(tau);
  if (ph.pivot) return ph.s0;
  return std::min(ph.s0 + ph.distance, rampState(ph.s0, ph.v0, ph.v1, ph.duration, tau - ph.t0).s);
}

double PathPlan::timeAt(double s) const {
  if (s <= 0.0 || phases_.empty()) return 0.0;
  if (s >= length_) return duration_;
  // The first phase that moves beyond s; within it s(t) is increasing: bisection.
  auto it = std::find_if(phases_.begin(), phases_.end(),
                         [s](const Phase& p) { return !p.pivot && p.s0 + p.distance >= s && p.distance > 0.0; });
  if (it == phases_.end()) return duration_;
  double lo = it->t0, hi = it->t0 + it->duration;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (arcLengthAt(mid) < s ? lo : hi) = mid;
  }
  return hi;
}

PathPlan::Projection PathPlan::project(const Eigen::Vector2d& p, double s_lo, double s_hi) const {
  Projection best;
  double best_d = std::numeric_limits<double>::infinity();
  auto consider = [&](double s) {
    Eigen::Vector2d q;
    double theta, kappa, dkappa;
    geometry(s, q, theta, kappa, dkappa);
    const double d = (p - q).norm();
    if (d < best_d) {
      best_d = d;
      const Eigen::Vector2d u = unitVector(theta);
      best.s = s;
      best.cross_track = u.x() * (p - q).y() - u.y() * (p - q).x();
    }
  };
  for (const Element& el : elements_) {
    const double a = std::max(s_lo, el.s0), b = std::min(s_hi, el.s0 + el.length);
    if (a > b) continue;
    if (el.phi == 0.0) {
      const Eigen::Vector2d u = unitVector(el.theta0);
      consider(std::clamp(el.s0 + (p - el.p0).dot(u), a, b));
      continue;
    }
    const double step = el.length / kFilletNodes;
    for (int i = 0; i < kFilletNodes; ++i) {  // each node chord, then the exact point on the arc there
      const double c0 = el.s0 + i * step;
      if (c0 + step < a || c0 > b) continue;
      const double u = segmentParameter(p, el.nodes[i], el.nodes[i + 1]);
      consider(std::clamp(c0 + u * step, a, b));
    }
  }
  if (!std::isfinite(best_d)) consider(std::clamp(s_lo, 0.0, length_));
  return best;
}

PathReference::PathReference(const PathParams& params, const Pose2D& start, std::vector<Eigen::Vector2d> points,
                             std::vector<bool> tool)
    : params_(params), start_(start), initial_points_(std::move(points)), initial_tool_(std::move(tool)) {
  const std::string e = params_.validate();
  if (!e.empty()) throw std::invalid_argument("path parameters: " + e);
  restart();
}

std::unique_ptr<ReferenceSource> PathReference::clone() const {
  return std::make_unique<PathReference>(params_, start_, initial_points_, initial_tool_);
}

void PathReference::restart() {
  has_plan_ = !initial_points_.empty();
  plan_t0_ = 0.0;
  plan_ = has_plan_ ? PathPlan(initial_points_, PathStart{start_, 0.0}, params_, initial_tool_) : PathPlan();
}

void PathReference::setPath(const std::vector<Eigen::Vector2d>& points, std::vector<bool> tool) {
  const double now = lastTime();
  PathStart from{start_, 0.0};
  if (has_plan_) {
    const Reference r = plan_.at(now - plan_t0_);
    from.pose = r.pose;
    from.v = std::max(0.0, r.v);
  }
  plan_ = PathPlan(points, from, params_, std::move(tool));  // throws before anything changes
  has_plan_ = true;
  plan_t0_ = now;
}

Reference PathReference::evaluate(double t) {
  if (has_plan_) return plan_.at(t - plan_t0_);
  Reference r;
  r.pose = start_;
  r.tool_down = false;
  r.stop = true;
  return r;
}

}  // namespace core
}  // namespace sowing_robot
