#include "sowing_robot/core/planning/coverage_planner.h"

// Boost.Geometry's buffer and envelope code, inlined here, trips GCC 12's -Wmaybe-uninitialized on a box it fills
// before reading (a false positive that -Werror would turn into a failed build).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>

#include "sowing_robot/core/common/types.h"
#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/core/planning/field.h"
#include "sowing_robot/core/planning/polygon_ops.h"

namespace sowing_robot {
namespace core {

namespace bg = boost::geometry;

const ParamTable<CoverageParams>& coverageTable() {
  using C = CoverageParams;
  static const ParamTable<C> table({
      integer("coverage/rows_per_pass", &C::rows_per_pass, 1, Limits::atLeast(1), "",
              "tool rows sown in one pass (working width = rows_per_pass x row_spacing)"),
      number("coverage/row_spacing", &C::row_spacing, 1.0, Limits::positive(), "m",
             "distance between the tool's rows (field/row_spacing)"),
      integer("coverage/headland_passes", &C::headland_passes, 2, Limits::atLeast(0), "",
              "passes of the working width round the boundary and every void, sown last"),
      text("coverage/heading", &C::heading, "auto",
           "swath heading in rad, or auto: the heading with the fewest swaths (edge directions and a sweep)"),
      number("coverage/min_turn_radius", &C::min_turn_radius, 0.5, Limits::positive(), "m",
             "every curve of the route keeps |curvature| <= 1/min_turn_radius (field/min_turn_radius)"),
      number("coverage/max_curvature_rate", &C::max_curvature_rate, 10.0, Limits::positive(), "1/m^2",
             "peak |dkappa/ds| of the turns (>= 1/(2 min_turn_radius^2); field/max_curvature_rate)"),
      choice("coverage/pattern", &C::pattern, RoutePattern::kAuto,
             {{"auto", RoutePattern::kAuto},
              {"boustrophedon", RoutePattern::kBoustrophedon},
              {"skip", RoutePattern::kSkip}},
             "swath order in a part: boustrophedon (neighbour after neighbour), skip (every second swath out, the "
             "others back), auto (skip when the working width is below 2 min_turn_radius)"),
      number("coverage/sample_spacing", &C::sample_spacing, 0.3, Limits::positive(), "m",
             "spacing of the route's points on its turns"),
      number("coverage/heading_step", &C::heading_step, M_PI / 36.0, Limits::above(0.0, M_PI / 2.0), "rad",
             "step of the heading sweep of heading auto"),
      number("coverage/run_out", &C::run_out, 0.0, Limits::nonNegative(), "m",
             "each swath is driven on this far past its end and the tool lowered this far past its start: the tool "
             "point's distance behind the axle; reference_generator and sow_field take the URDF's tool_link offset "
             "(0.45 m) "
             "when it is not set"),
  });
  return table;
}

CoverageParams::CoverageParams() { coverageTable().applyDefaults(*this); }

std::string CoverageParams::parseHeading(bool& is_auto, double& out) const {
  is_auto = heading == "auto";
  if (is_auto) return "";
  char* end = nullptr;
  const double v = std::strtod(heading.c_str(), &end);
  if (heading.empty() || end == heading.c_str() || *end != '\0' || !std::isfinite(v))
    return "coverage/heading = \"" + heading + "\" must be auto or a finite number of radians";
  out = v;
  return "";
}

std::string CoverageParams::validate() const {
  std::string e = coverageTable().checkRanges(*this);
  if (!e.empty()) return e;
  bool is_auto = false;
  double h = 0.0;
  e = parseHeading(is_auto, h);
  if (!e.empty()) return e;
  const double rate_min = 0.5 / (min_turn_radius * min_turn_radius);
  if (max_curvature_rate < rate_min)
    return "coverage/max_curvature_rate = " + formatNumber(max_curvature_rate) +
           " 1/m^2 must be >= 1/(2 coverage/min_turn_radius^2) = " + formatNumber(rate_min) + " 1/m^2";
  return "";
}

std::vector<RowSegment> CoveragePlan::rows() const {
  std::vector<RowSegment> out;
  for (const Swath& s : swaths) out.insert(out.end(), s.rows.begin(), s.rows.end());
  out.insert(out.end(), headland_rows.begin(), headland_rows.end());
  return out;
}

std::size_t CoveragePlan::swathRows() const {
  std::size_t n = 0;
  for (const Swath& s : swaths) n += s.rows.size();
  return n;
}

bool headlandSide(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const CoverageParams& params) {
  return (q - p).norm() - params.run_out >= params.workingWidth();
}

std::vector<RowSegment> headlandSideRows(const Eigen::Vector2d& p, const Eigen::Vector2d& q,
                                         const CoverageParams& params) {
  std::vector<RowSegment> out;
  const double length = (q - p).norm();
  if (!(length > params.run_out)) return out;
  const Eigen::Vector2d u = (q - p) / length, left(-u.y(), u.x());
  const Eigen::Vector2d end = q - params.run_out * u;
  for (int r = 0; r < params.rows_per_pass; ++r) {
    const Eigen::Vector2d shift = ((r - 0.5 * (params.rows_per_pass - 1)) * params.row_spacing) * left;
    out.push_back({p + shift, end + shift});
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------
// The boundary's checks

namespace {

std::string ringError(const Ring& ring, const std::string& name) {
  if (ring.size() < 3) return name + " has " + std::to_string(ring.size()) + " points (needs >= 3)";
  for (const Eigen::Vector2d& p : ring)
    if (!p.allFinite()) return name + " has a non-finite point";
  const geo::Polygon poly = geo::toPolygon(ring);
  // Before the validity check: a crossing ring has no orientation, which is_valid would report first.
  if (bg::intersects(poly)) return name + " is not a simple polygon: it intersects itself";
  std::string reason;
  if (!bg::is_valid(poly, reason)) return name + " is not a simple polygon: " + reason;
  return "";
}

}  // namespace

std::string checkBoundary(const FieldBoundary& field) {
  std::string e = ringError(field.outer, "field boundary");
  if (!e.empty()) return e;
  const geo::Polygon outer = geo::toPolygon(field.outer);
  for (std::size_t i = 0; i < field.voids.size(); ++i) {
    const std::string name = "void " + std::to_string(i);
    e = ringError(field.voids[i], name);
    if (!e.empty()) return e;
    const geo::Polygon v = geo::toPolygon(field.voids[i]);
    // Touching the boundary from outside is outside too: only a void with area inside the field counts.
    geo::MultiPolygon common;
    bg::intersection(outer, v, common);
    if (bg::area(common) <= 0.0) return name + " lies outside the field boundary";
  }
  for (std::size_t i = 0; i < field.circles.size(); ++i) {
    const std::string name = "circular void " + std::to_string(i);
    e = field.circles[i].validate();
    if (!e.empty()) return name + ": " + e;
    geo::MultiPolygon common;
    bg::intersection(outer, geo::circle({field.circles[i].x, field.circles[i].y}, field.circles[i].radius), common);
    if (bg::area(common) <= 0.0) return name + " lies outside the field boundary";
  }
  return "";
}

// ---------------------------------------------------------------------------------------------------
// Turns

namespace {

struct Pose {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  double h = 0.0;
};

Eigen::Vector2d rotate(const Eigen::Vector2d& v, double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

// 5-point Gauss-Legendre on [0, 1].
constexpr double kGaussX[5] = {0.04691007703066800, 0.23076534494715845, 0.5, 0.76923465505284155, 0.95308992296933200};
constexpr double kGaussW[5] = {0.11846344252809454, 0.23931433524968324, 0.28444444444444444, 0.23931433524968324,
                               0.11846344252809454};

/// A left turn by phi whose curvature ramps 0 -> k -> 0 by half cosines (peak |dkappa/ds| = rate) and holds k
/// between them: the field's rounded turn (field.h) for any angle. k is the largest curvature up to k_max
/// whose ramps fit in phi.
class RampTurn {
 public:
  RampTurn() = default;
  RampTurn(double phi, double k_max, double rate) : phi_(phi) {
    if (phi <= 0.0) return;
    k_ = std::min(k_max, std::sqrt(2.0 * rate * phi / M_PI));
    ramp_ = 0.5 * M_PI * k_ / rate;
    hold_ = std::max(0.0, (phi - k_ * ramp_) / k_);
  }
  double length() const { return 2.0 * ramp_ + hold_; }
  double peak() const { return k_; }
  /// Heading [rad], curvature [1/m] and dkappa/ds [1/m^2] at arc length s.
  void state(double s, double& theta, double& kappa, double& dkappa) const {
    if (k_ == 0.0) {
      theta = kappa = dkappa = 0.0;
      return;
    }
    const double len = length();
    if (s <= ramp_) {
      rampState(s, theta, kappa, dkappa);
    } else if (s <= ramp_ + hold_) {
      theta = 0.5 * k_ * ramp_ + k_ * (s - ramp_);
      kappa = k_;
      dkappa = 0.0;
    } else {
      rampState(std::max(0.0, len - s), theta, kappa, dkappa);
      theta = phi_ - theta;
      dkappa = -dkappa;
    }
  }
  /// Displacement from arc length a to b, integrated numerically piece by piece (Gauss-Legendre would lose its
  /// accuracy across the kinks of the curvature profile at the ramps' ends).
  Eigen::Vector2d displacement(double a, double b, double max_step) const {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    const double cuts[4] = {0.0, ramp_, ramp_ + hold_, length()};
    for (int c = 0; c < 3; ++c) {
      const double lo = std::max(a, cuts[c]), hi = std::min(b, cuts[c + 1]);
      if (hi <= lo) continue;
      const int n = std::max(1, static_cast<int>(std::ceil((hi - lo) / max_step)));
      const double h = (hi - lo) / n;
      for (int i = 0; i < n; ++i)
        for (int g = 0; g < 5; ++g) {
          double th, k, dk;
          state(lo + (i + kGaussX[g]) * h, th, k, dk);
          sum += kGaussW[g] * h * unitVector(th);
        }
    }
    return sum;
  }
  Eigen::Vector2d end() const { return displacement(0.0, length(), 0.25); }

 private:
  void rampState(double tau, double& theta, double& kappa, double& dkappa) const {
    const double w = M_PI / ramp_;
    kappa = 0.5 * k_ * (1.0 - std::cos(w * tau));
    theta = 0.5 * k_ * (tau - std::sin(w * tau) / w);
    dkappa = 0.5 * k_ * w * std::sin(w * tau);
  }
  double phi_ = 0.0, k_ = 0.0, ramp_ = 0.0, hold_ = 0.0;
};

/// Turn-straight-turn between two poses: the turns are RampTurns (left sigma = +1, right -1).
struct TurnStraightTurn {
  double phi1 = 0.0, straight = 0.0, phi2 = 0.0;
  int sigma1 = 1, sigma2 = 1;
  double length = std::numeric_limits<double>::infinity();
};

double wrapTwoPi(double a) {
  a = std::fmod(a, 2.0 * M_PI);
  return a < 0.0 ? a + 2.0 * M_PI : a;
}

/// Builds the route: its points, tool flags, lengths and the peaks of its curves.
class RouteBuilder {
 public:
  RouteBuilder(const CoverageParams& params)
      : params_(params), k_max_(1.0 / params.min_turn_radius), rate_(params.max_curvature_rate) {
    for (int i = 0; i <= kTable; ++i) {
      const RampTurn t(2.0 * M_PI * i / kTable, k_max_, rate_);
      table_[i] = {t.end(), t.length()};
    }
  }

  CoveragePath path;
  double length = 0.0, up_length = 0.0, peak_kappa = 0.0, peak_rate = 0.0;
  int straight_joins = 0;

  void start(const Eigen::Vector2d& p) {
    path.points = {p};
    path.tool_down.clear();
  }
  const Eigen::Vector2d& last() const { return path.points.back(); }
  void lineTo(const Eigen::Vector2d& p, bool tool) {
    const double d = (p - last()).norm();
    if (d < 1e-9) return;
    path.points.push_back(p);
    path.tool_down.push_back(tool);
    length += d;
    if (!tool) up_length += d;
  }

  /// Tool up to p; a turn that ended within rounding of p is moved onto it rather than followed by a stub.
  void arrive(const Eigen::Vector2d& p) {
    if (path.points.size() >= 2 && (last() - p).norm() < 1e-4) {
      const double d =
          (path.points[path.points.size() - 2] - p).norm() - (path.points[path.points.size() - 2] - last()).norm();
      length += d;
      up_length += d;
      path.points.back() = p;
      return;
    }
    lineTo(p, false);
  }

  /// Tool up from a to b (the route is at a.p).
  void connect(const Pose& a, const Pose& b) {
    const Eigen::Vector2d local = rotate(b.p - a.p, -a.h);
    const bool opposite = std::fabs(wrapAngle(b.h - a.h - M_PI)) < 1e-6;
    if (opposite && std::fabs(local.y()) > 1e-6) {
      // A U-turn between the ends, after (or before) a straight to the later of the two along-row positions.
      if (local.x() > 1e-4) lineTo(a.p + local.x() * unitVector(a.h), false);
      const Pose turn_start{last(), a.h};
      uTurn(turn_start, local.y());
      arrive(b.p);
      return;
    }
    if ((b.p - a.p).norm() < 1e-9 && std::fabs(wrapAngle(b.h - a.h)) < 1e-6) return;
    const TurnStraightTurn c = solve(a, b);
    if (!std::isfinite(c.length)) {
      // No turn-straight-turn reaches b: a straight line, counted (the plan reports it).
      ++straight_joins;
      arrive(b.p);
      return;
    }
    Pose at = a;
    at = rampTurn(at, c.phi1, c.sigma1);
    lineTo(at.p + c.straight * unitVector(at.h), false);
    at.p = last();
    rampTurn(at, c.phi2, c.sigma2);
    arrive(b.p);
  }

 private:
  static constexpr int kTable = 720;

  const HeadlandTurn& headlandTurn(double width) {
    const long long key = std::llround(width * 1e6);
    auto it = turns_.find(key);
    if (it == turns_.end()) it = turns_.emplace(key, HeadlandTurn(width, k_max_, rate_)).first;
    return it->second;
  }

  /// The field's U-turn of width |side| to the left (side > 0) or right from pose a.
  void uTurn(const Pose& a, double side) {
    const HeadlandTurn& t = headlandTurn(std::fabs(side));
    const double mirror = side > 0.0 ? 1.0 : -1.0;
    const int n = std::max(2, static_cast<int>(std::ceil(t.length() / params_.sample_spacing)));
    Eigen::Vector2d p;
    double th, k, dk;
    for (int i = 1; i <= n; ++i) {
      t.evaluate(t.length() * i / n, p, th, k, dk);
      peak_kappa = std::max(peak_kappa, std::fabs(k));
      peak_rate = std::max(peak_rate, std::fabs(dk));
      lineTo(a.p + rotate(Eigen::Vector2d(p.x(), mirror * p.y()), a.h), false);
    }
    // Peaks between the samples: the turn's own.
    peak_kappa = std::max(peak_kappa, t.peakCurvature());
  }

  /// A RampTurn by phi to the left (sigma 1) or right from a; returns the pose at its end.
  Pose rampTurn(const Pose& a, double phi, int sigma) {
    const RampTurn t(phi, k_max_, rate_);
    if (t.length() < 1e-4) return {a.p, a.h + sigma * phi};  // a heading change of a few microradians
    const int n = std::max(2, static_cast<int>(std::ceil(t.length() / params_.sample_spacing)));
    Eigen::Vector2d local = Eigen::Vector2d::Zero();
    double th = 0.0, k, dk;
    for (int i = 1; i <= n; ++i) {
      const double s0 = t.length() * (i - 1) / n, s1 = t.length() * i / n;
      local += t.displacement(s0, s1, 0.25);
      t.state(s1, th, k, dk);
      lineTo(a.p + rotate(Eigen::Vector2d(local.x(), sigma * local.y()), a.h), false);
    }
    peak_kappa = std::max(peak_kappa, t.peak());
    if (t.peak() > 0.0) peak_rate = std::max(peak_rate, rate_);
    return {last(), a.h + sigma * phi};
  }

  /// Displacement and length of a left RampTurn by phi in [0, 2 pi], from the table (linear between entries).
  void tabled(double phi, Eigen::Vector2d& d, double& len) const {
    const double x = std::clamp(phi / (2.0 * M_PI) * kTable, 0.0, static_cast<double>(kTable));
    const int i = std::min(kTable - 1, static_cast<int>(x));
    const double f = x - i;
    d = (1.0 - f) * table_[i].first + f * table_[i + 1].first;
    len = (1.0 - f) * table_[i].second + f * table_[i + 1].second;
  }

  /// The shortest turn-straight-turn from a to b (length infinite when none is found).
  TurnStraightTurn solve(const Pose& a, const Pose& b) const {
    const Eigen::Vector2d target = rotate(b.p - a.p, -a.h);
    const double delta = b.h - a.h;
    TurnStraightTurn best;
    for (const int s1 : {1, -1})
      for (const int s2 : {1, -1}) {
        // Residual across the straight (0 at a solution) and the straight's length, for phi1; exact or tabled.
        auto residual = [&](double phi1, bool exact, double& straight, double& len, double& phi2) {
          phi2 = wrapTwoPi(s2 * (delta - s1 * phi1));
          Eigen::Vector2d d1, d2;
          double l1, l2;
          if (exact) {
            const RampTurn t1(phi1, k_max_, rate_), t2(phi2, k_max_, rate_);
            d1 = t1.end();
            d2 = t2.end();
            l1 = t1.length();
            l2 = t2.length();
          } else {
            tabled(phi1, d1, l1);
            tabled(phi2, d2, l2);
          }
          const double m = s1 * phi1;
          const Eigen::Vector2d q =
              target - Eigen::Vector2d(d1.x(), s1 * d1.y()) - rotate(Eigen::Vector2d(d2.x(), s2 * d2.y()), m);
          const Eigen::Vector2d u = unitVector(m);
          straight = u.dot(q);
          len = l1 + l2 + straight;
          return u.x() * q.y() - u.y() * q.x();
        };
        double st, len, phi2;
        double prev_phi = 0.0, prev_f = residual(0.0, false, st, len, phi2);
        for (int i = 1; i <= kTable; ++i) {
          const double phi = 2.0 * M_PI * i / kTable;
          const double f = residual(phi, false, st, len, phi2);
          if ((prev_f <= 0.0) != (f <= 0.0) && st > -1.0) {
            // Bisection on the exact residual; a sign change across phi2's wrap is not a root (checked below).
            double lo = prev_phi, hi = phi;
            double flo = residual(lo, true, st, len, phi2);
            for (int it = 0; it < 40; ++it) {
              const double mid = 0.5 * (lo + hi);
              const double fm = residual(mid, true, st, len, phi2);
              if ((fm <= 0.0) == (flo <= 0.0)) {
                lo = mid;
                flo = fm;
              } else {
                hi = mid;
              }
            }
            const double phi1 = 0.5 * (lo + hi);
            const double fr = residual(phi1, true, st, len, phi2);
            if (std::fabs(fr) < 1e-6 && st >= -1e-9 && len < best.length) {
              best.phi1 = phi1;
              best.phi2 = phi2;
              best.straight = std::max(0.0, st);
              best.sigma1 = s1;
              best.sigma2 = s2;
              best.length = len;
            }
          }
          prev_phi = phi;
          prev_f = f;
        }
      }
    return best;
  }

  const CoverageParams& params_;
  double k_max_, rate_;
  std::array<std::pair<Eigen::Vector2d, double>, kTable + 1> table_;
  std::map<long long, HeadlandTurn> turns_;
};

// ---------------------------------------------------------------------------------------------------
// Swaths

/// The inner field cut by parallel lines at heading h, one working width apart.
struct LineSet {
  double heading = 0.0;
  Eigen::Vector2d u, n;                                      // along, across (left of along)
  std::vector<double> offsets;                               // across position of each line [m]
  std::vector<std::vector<std::pair<double, double>>> segs;  // per line: along intervals, sorted
  int count = 0;                                             // swaths
};

LineSet cutLines(const geo::MultiPolygon& inner, double heading, double width) {
  LineSet ls;
  ls.heading = heading;
  ls.u = unitVector(heading);
  ls.n = Eigen::Vector2d(-ls.u.y(), ls.u.x());
  double lmin = std::numeric_limits<double>::infinity(), lmax = -lmin, amin = lmin, amax = -lmin;
  bg::for_each_point(inner, [&](const geo::Point& q) {
    const Eigen::Vector2d p = geo::toVector(q);
    lmin = std::min(lmin, p.dot(ls.n));
    lmax = std::max(lmax, p.dot(ls.n));
    amin = std::min(amin, p.dot(ls.u));
    amax = std::max(amax, p.dot(ls.u));
  });
  const double across = lmax - lmin;
  // Boost's offsets are exact to a few micrometres (a rotated rectangle shrunk by 2 m: 3e-6 m): a field whose
  // width is a whole number of swaths must not get one more for that.
  const int n = std::max(1, static_cast<int>(std::ceil(across / width - 1e-4)));
  // One width apart from the first edge; the last line moved in so its strip ends at the far edge (it overlaps
  // its neighbour rather than the headland); a field narrower than one width gets one centred line.
  for (int j = 0; j < n; ++j) ls.offsets.push_back(lmin + (j + 0.5) * width);
  if (n == 1)
    ls.offsets[0] = lmin + 0.5 * across;
  else
    ls.offsets.back() = std::min(ls.offsets.back(), lmax - 0.5 * width);
  geo::MultiLine lines;
  for (const double o : ls.offsets) {
    geo::Line l;
    l.push_back(geo::toPoint((amin - 1.0) * ls.u + o * ls.n));
    l.push_back(geo::toPoint((amax + 1.0) * ls.u + o * ls.n));
    lines.push_back(l);
  }
  geo::MultiLine clipped;
  bg::intersection(lines, inner, clipped);
  ls.segs.assign(n, {});
  for (const geo::Line& l : clipped) {
    if (l.size() < 2) continue;
    double a0 = std::numeric_limits<double>::infinity(), a1 = -a0, lat = 0.0;
    for (const geo::Point& q : l) {
      const Eigen::Vector2d p = geo::toVector(q);
      a0 = std::min(a0, p.dot(ls.u));
      a1 = std::max(a1, p.dot(ls.u));
      lat += p.dot(ls.n) / l.size();
    }
    if (a1 - a0 < 0.01) continue;  // a touch of a corner, not a swath
    int best = 0;
    for (int j = 1; j < n; ++j)
      if (std::fabs(ls.offsets[j] - lat) < std::fabs(ls.offsets[best] - lat)) best = j;
    ls.segs[best].emplace_back(a0, a1);
  }
  for (auto& s : ls.segs) {
    std::sort(s.begin(), s.end());
    // Pieces of one swath that the clipping returned apart (a vertex on the line) are joined again.
    std::vector<std::pair<double, double>> merged;
    for (const auto& iv : s) {
      if (!merged.empty() && iv.first <= merged.back().second + 1e-9)
        merged.back().second = std::max(merged.back().second, iv.second);
      else
        merged.push_back(iv);
    }
    s = std::move(merged);
    ls.count += static_cast<int>(s.size());
  }
  return ls;
}

/// A part of the inner field that sweeps as one: one swath on each of consecutive lines, each overlapping
/// the next along the lines.
struct Part {
  int first_line = 0;
  std::vector<std::pair<double, double>> segs;
};

bool overlaps(const std::pair<double, double>& a, const std::pair<double, double>& b) {
  return std::min(a.second, b.second) - std::max(a.first, b.first) > 0.0;
}

std::vector<Part> splitParts(const LineSet& ls) {
  std::vector<Part> parts;
  std::vector<int> prev_part;  // part of each segment on the previous line
  for (std::size_t i = 0; i < ls.segs.size(); ++i) {
    std::vector<int> part(ls.segs[i].size(), -1);
    for (std::size_t j = 0; j < ls.segs[i].size(); ++j) {
      if (i > 0) {
        int hits = 0, prev = -1;
        for (std::size_t q = 0; q < ls.segs[i - 1].size(); ++q)
          if (overlaps(ls.segs[i - 1][q], ls.segs[i][j])) {
            ++hits;
            prev = static_cast<int>(q);
          }
        if (hits == 1) {
          int back = 0;
          for (const auto& s : ls.segs[i]) back += overlaps(ls.segs[i - 1][prev], s) ? 1 : 0;
          if (back == 1 && prev_part[prev] >= 0) {
            part[j] = prev_part[prev];
            parts[part[j]].segs.push_back(ls.segs[i][j]);
            continue;
          }
        }
      }
      part[j] = static_cast<int>(parts.size());
      parts.push_back({static_cast<int>(i), {ls.segs[i][j]}});
    }
    prev_part = std::move(part);
  }
  return parts;
}

/// The order of a part's m lines (0 = its first line): boustrophedon, or skip (every second out, the rest back).
std::vector<int> lineOrder(int m, RoutePattern pattern) {
  std::vector<int> order;
  if (pattern == RoutePattern::kSkip && m > 2) {
    for (int i = 0; i < m; i += 2) order.push_back(i);
    for (int i = (m - 1) % 2 == 1 ? m - 1 : m - 2; i >= 1; i -= 2) order.push_back(i);
  } else {
    for (int i = 0; i < m; ++i) order.push_back(i);
  }
  return order;
}

Swath makeSwath(const LineSet& ls, int line, const std::pair<double, double>& seg, int dir, int part,
                const CoverageParams& p) {
  Swath s;
  s.line = line;
  s.part = part;
  const Eigen::Vector2d base = ls.offsets[line] * ls.n;
  const Eigen::Vector2d lo = base + seg.first * ls.u, hi = base + seg.second * ls.u;
  s.a = dir > 0 ? lo : hi;
  s.b = dir > 0 ? hi : lo;
  for (int r = 0; r < p.rows_per_pass; ++r) {
    const Eigen::Vector2d shift = ((r - 0.5 * (p.rows_per_pass - 1)) * p.row_spacing) * ls.n;
    s.rows.push_back({s.a + shift, s.b + shift});
  }
  return s;
}

/// The region's boundary with every corner rounded to at least radius rho: a closing (grow, shrink: rounds the
/// concave corners) and then an opening (shrink, grow: rounds the convex ones), the two shrinks in one. The last
/// grow draws the convex arcs; a 1 mm simplification drops the near-repeated vertices the offsets leave.
geo::MultiPolygon rounded(const geo::MultiPolygon& region, double rho) {
  const geo::MultiPolygon r = geo::offset(geo::offset(geo::offset(region, rho), -2.0 * rho), rho);
  geo::MultiPolygon out;
  bg::simplify(r, out, 1e-3);
  return out;
}

std::vector<Ring> ringsOf(const geo::MultiPolygon& mp) {
  std::vector<Ring> out;
  for (const geo::Polygon& poly : mp) {
    out.push_back(geo::toRing(poly.outer()));
    for (const auto& inner : poly.inners()) out.push_back(geo::toRing(inner));
  }
  return out;
}

}  // namespace

CoveragePlan planCoverage(const FieldBoundary& field, const CoverageParams& params) {
  std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  e = checkBoundary(field);
  if (!e.empty()) throw std::invalid_argument(e);
  bool auto_heading = false;
  double heading = 0.0;
  params.parseHeading(auto_heading, heading);

  const double w = params.workingWidth();
  const double k = params.headland_passes;
  CoveragePlan plan;
  plan.working_width = w;
  plan.pattern = params.pattern != RoutePattern::kAuto              ? params.pattern
                 : w < 2.0 * params.min_turn_radius * (1.0 - 1e-12) ? RoutePattern::kSkip
                                                                    : RoutePattern::kBoustrophedon;

  const geo::MultiPolygon outer{geo::outerPolygon(field)};
  const geo::MultiPolygon voids = geo::voidPolygons(field);
  plan.field.push_back(geo::toRing(outer.front().outer()));
  for (const geo::Polygon& v : voids) plan.field.push_back(geo::toRing(v.outer()));

  geo::MultiPolygon inner;
  bg::difference(geo::offset(outer, -k * w), geo::offset(voids, k * w), inner);
  const std::string narrow = "the field is narrower than one swath (" + formatNumber(w) + " m) plus its " +
                             std::to_string(params.headland_passes) + " headland pass(es) of " + formatNumber(w) +
                             " m on each side";
  // Room for one swath somewhere: the inner field holds a strip of the working width (less 0.1 %, for Boost's
  // offsets, exact to micrometres).
  const double tiny = 1e-9 * std::max(1.0, bg::area(outer));
  if (bg::area(inner) <= tiny || bg::area(geo::offset(inner, -0.5 * w * (1.0 - 1e-3))) <= tiny)
    throw std::invalid_argument(narrow);
  plan.inner_field = ringsOf(inner);

  // The swath heading: the given one, or the one with the fewest swaths (every edge direction of the boundary,
  // the longest first, then a sweep; the first of equals wins).
  LineSet lines;
  if (auto_heading) {
    std::vector<std::pair<double, double>> edges;  // (-length, direction in [0, pi))
    const Ring& o = field.outer;
    for (std::size_t i = 0; i < o.size(); ++i) {
      const Eigen::Vector2d d = o[(i + 1) % o.size()] - o[i];
      if (d.norm() > 0.0) edges.emplace_back(-d.norm(), std::fmod(std::atan2(d.y(), d.x()) + 2.0 * M_PI, M_PI));
    }
    std::sort(edges.begin(), edges.end());
    std::vector<double> candidates;
    for (const auto& ed : edges) candidates.push_back(ed.second);
    for (double h = 0.0; h < M_PI - 1e-12; h += params.heading_step) candidates.push_back(h);
    // Two stages: every candidate on a coarse grid (lines four widths apart over the inner field simplified to a
    // tenth of the width: a quarter of the swaths, to within a few), then the best few at the working width.
    geo::MultiPolygon coarse;
    bg::simplify(inner, coarse, 0.1 * w);
    std::vector<std::pair<int, std::size_t>> rough;  // (coarse count, candidate)
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const int count = cutLines(coarse, candidates[c], 4.0 * w).count;
      if (count > 0) rough.emplace_back(count, c);
    }
    std::stable_sort(rough.begin(), rough.end());
    bool have = false;
    std::size_t have_index = 0;
    for (std::size_t r = 0; r < rough.size() && r < 4; ++r) {
      LineSet ls = cutLines(inner, candidates[rough[r].second], w);
      if (ls.count > 0 &&
          (!have || ls.count < lines.count || (ls.count == lines.count && rough[r].second < have_index))) {
        lines = std::move(ls);
        have = true;
        have_index = rough[r].second;
      }
    }
  } else {
    lines = cutLines(inner, heading, w);
  }
  if (lines.count == 0) throw std::invalid_argument(narrow);
  plan.heading = std::fmod(std::fmod(lines.heading, M_PI) + M_PI, M_PI);

  // Parts, chained nearest entry first; the first part starts at the first line, along the heading.
  const std::vector<Part> parts = splitParts(lines);
  plan.parts = static_cast<int>(parts.size());
  std::vector<bool> done(parts.size(), false);
  RouteBuilder route(params);
  bool started = false;
  Pose at;
  for (std::size_t visited = 0; visited < parts.size(); ++visited) {
    int best = -1, best_dir = 1;
    bool best_mirror = false;
    double best_cost = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < parts.size(); ++c) {
      if (done[c]) continue;
      if (!started) {
        best = static_cast<int>(c);
        break;
      }
      const Part& pc = parts[c];
      const int m = static_cast<int>(pc.segs.size());
      for (const bool mirror : {false, true})
        for (const int dir : {1, -1}) {
          const int first = lineOrder(m, plan.pattern).front();
          const int li = mirror ? m - 1 - first : first;
          const Swath s = makeSwath(lines, pc.first_line + li, pc.segs[li], dir, static_cast<int>(c), params);
          const double cost = (s.a - at.p).norm();
          if (cost < best_cost) {
            best_cost = cost;
            best = static_cast<int>(c);
            best_dir = dir;
            best_mirror = mirror;
          }
        }
    }
    done[best] = true;
    const Part& pc = parts[best];
    const int m = static_cast<int>(pc.segs.size());
    int dir = best_dir;
    for (const int o : lineOrder(m, plan.pattern)) {
      const int li = best_mirror ? m - 1 - o : o;
      const Swath s = makeSwath(lines, pc.first_line + li, pc.segs[li], dir, best, params);
      const Pose entry{s.a, std::atan2(s.b.y() - s.a.y(), s.b.x() - s.a.x())};
      if (!started) {
        route.start(s.a);
        started = true;
      } else {
        route.connect(at, entry);
      }
      // The tool point trails the axle by run_out: it enters the row run_out after the swath's start and reaches its
      // end run_out past it, in the headland (k working widths of room).
      const Eigen::Vector2d on = params.run_out * unitVector(entry.h);
      route.lineTo(s.a + on, false);
      route.lineTo(s.b + on, true);
      at = {s.b + on, entry.h};
      plan.swaths.push_back(s);
      dir = -dir;
    }
  }

  // The headland passes, the innermost first, each ring a closed loop from its point nearest the route's end,
  // driven the way that turns least onto it; corners rounded so every curve keeps min_turn_radius (10 % spare:
  // the rounding's uneven chords put the circle through three vertices up to 6 % tighter than the arc). Its straight
  // sides are sown as rows (headlandSide), its corners not: there the trailing tool point swings off the ring's line.
  const double rho = 1.1 * params.min_turn_radius;
  for (int pass = params.headland_passes - 1; pass >= 0; --pass) {
    const double d = (pass + 0.5) * w;
    geo::MultiPolygon region;
    bg::difference(geo::offset(outer, -d), geo::offset(voids, d), region);
    std::vector<Ring> rings = ringsOf(rounded(region, rho));
    std::vector<bool> driven(rings.size(), false);
    for (std::size_t count = 0; count < rings.size(); ++count) {
      std::size_t best_ring = 0, best_vertex = 0;
      double best_dist = std::numeric_limits<double>::infinity();
      for (std::size_t r = 0; r < rings.size(); ++r) {
        if (driven[r] || rings[r].size() < 3) continue;
        for (std::size_t v = 0; v < rings[r].size(); ++v) {
          const double dist = (rings[r][v] - at.p).norm();
          if (dist < best_dist) {
            best_dist = dist;
            best_ring = r;
            best_vertex = v;
          }
        }
      }
      if (!std::isfinite(best_dist)) break;
      driven[best_ring] = true;
      const Ring& ring = rings[best_ring];
      Ring loop;
      for (std::size_t i = 0; i < ring.size(); ++i) loop.push_back(ring[(best_vertex + i) % ring.size()]);
      auto headingOf = [](const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
        return std::atan2(to.y() - from.y(), to.x() - from.x());
      };
      const double forward = headingOf(loop[0], loop[1]), backward = headingOf(loop[0], loop.back());
      if (std::fabs(wrapAngle(backward - at.h)) < std::fabs(wrapAngle(forward - at.h)))
        std::reverse(loop.begin() + 1, loop.end());
      route.connect(at, {loop[0], headingOf(loop[0], loop[1])});
      // Tool down on the straight sides, each a row of the plan; up on the corners' chords.
      for (std::size_t i = 1; i <= loop.size(); ++i) {
        const Eigen::Vector2d &p = loop[i - 1], &q = loop[i % loop.size()];
        const bool side = headlandSide(p, q, params);
        route.lineTo(q, side);
        if (!side) continue;
        const std::vector<RowSegment> rows = headlandSideRows(p, q, params);
        plan.headland_rows.insert(plan.headland_rows.end(), rows.begin(), rows.end());
      }
      at = {loop[0], headingOf(loop.back(), loop[0])};
      plan.headland_rings.push_back(loop);
      // The ring's own curvature: its corners' circles through three vertices (Menger curvature).
      for (std::size_t i = 0; i < loop.size(); ++i) {
        const Eigen::Vector2d &p0 = loop[(i + loop.size() - 1) % loop.size()], &p1 = loop[i],
                              &p2 = loop[(i + 1) % loop.size()];
        const Eigen::Vector2d a = p1 - p0, b = p2 - p1, c = p2 - p0;
        const double denom = a.norm() * b.norm() * c.norm();
        if (denom > 0.0)
          route.peak_kappa = std::max(route.peak_kappa, 2.0 * std::fabs(a.x() * b.y() - a.y() * b.x()) / denom);
      }
    }
  }

  plan.route = std::move(route.path);
  plan.path_length = route.length;
  plan.turn_length = route.up_length;
  plan.peak_curvature = route.peak_kappa;
  plan.peak_curvature_rate = route.peak_rate;
  plan.straight_joins = route.straight_joins;
  return plan;
}

CoveragePath coverageFrom(const CoveragePlan& plan, const Pose2D& start, const CoverageParams& params) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  if (!std::isfinite(start.x) || !std::isfinite(start.y) || !std::isfinite(start.theta))
    throw std::invalid_argument("coverageFrom: the start pose must be finite");
  if (plan.route.points.size() < 2 || plan.swaths.empty())
    throw std::invalid_argument("coverageFrom: the plan has no route");
  const Swath& first = plan.swaths.front();
  RouteBuilder approach(params);
  approach.start({start.x, start.y});
  approach.connect({{start.x, start.y}, start.theta},
                   {first.a, std::atan2(first.b.y() - first.a.y(), first.b.x() - first.a.x())});
  CoveragePath out = std::move(approach.path);
  out.points.back() = plan.route.points.front();
  out.points.insert(out.points.end(), plan.route.points.begin() + 1, plan.route.points.end());
  out.tool_down.insert(out.tool_down.end(), plan.route.tool_down.begin(), plan.route.tool_down.end());
  return out;
}

CoveragePath coverageJoin(const Pose2D& from, const Pose2D& to, const CoverageParams& params) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  for (const Pose2D* p : {&from, &to})
    if (!std::isfinite(p->x) || !std::isfinite(p->y) || !std::isfinite(p->theta))
      throw std::invalid_argument("coverageJoin: the poses must be finite");
  RouteBuilder join(params);
  join.start({from.x, from.y});
  join.connect({{from.x, from.y}, from.theta}, {{to.x, to.y}, to.theta});
  return std::move(join.path);
}

}  // namespace core
}  // namespace sowing_robot
