#include "sowing_robot/core/planning/detour.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace core {

namespace {
constexpr double kPlanSlack = 1e-3;  ///< the plan keeps this much more than the clearance [m]
constexpr double kCheckStep = 0.02;  ///< along-row sampling of a detour against other obstacles [m]
constexpr double kMinRamp = 0.05;    ///< a shorter up ramp (obstacle at the row start) is no ramp [m]

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), f, a, b, c, d);
  return buf;
}

std::string indexList(const std::vector<std::size_t>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
  return s;
}

/// Cycloidal rise 0 -> 1 over tau in [0, 1]: value and derivatives with respect to tau.
void cycloid(double tau, double& f, double& f1, double& f2, double& f3) {
  const double w = 2.0 * M_PI;
  double s, c;
  s = std::sin(w * tau);
  c = std::cos(w * tau);
  f = tau - s / w;
  f1 = 1.0 - c;
  f2 = w * s;
  f3 = w * w * c;
}

/// An obstacle in row coordinates.
struct Local {
  double a = 0.0, l = 0.0, R = 0.0;  ///< along, lateral (+ left), planning radius [m]
  bool on_row = false;               ///< the row line crosses its inflated disc
};

/// Where the row line enters obstacle k's inflated disc.
double entry(const Local& o) { return o.a - std::sqrt(std::max(0.0, o.R * o.R - o.l * o.l)); }
}  // namespace

const char* AvoidanceStatus::name(Code c) {
  switch (c) {
    case Code::kOk: return "ok";
    case Code::kStoppedShort: return "stopped_short";
    case Code::kNoSafeWay: return "no_safe_way";
  }
  return "?";
}

const ParamTable<AvoidanceParams>& avoidanceTable() {
  using A = AvoidanceParams;
  static const ParamTable<A> table({
      flag("plan_detours", &A::plan_detours, true,
           "plan detours around the obstacles inflated by the footprint; false: the thesis field (repulsion only)"),
      number("safety_margin", &A::safety_margin, 0.1, Limits::nonNegative(), "m",
             "body clearance the plan keeps from every obstacle"),
      number("max_curvature", &A::max_curvature, 2.0, Limits::positive(), "1/m", "curvature of the detours"),
      number("max_yaw_rate", &A::max_yaw_rate, 1.5, Limits::positive(), "rad/s",
             "|omega| of the reference on a detour"),
      number("max_lateral_accel", &A::max_lateral_accel, 1.5, Limits::positive(), "m/s^2",
             "|v omega| of the reference on a detour"),
      number("max_offset", &A::max_offset, 5.0, Limits::positive(), "m",
             "widest sideways detour; a wider group is 'no safe way'"),
      number("stop_margin", &A::stop_margin, 0.15, Limits::nonNegative(), "m",
             "extra clearance of a stop before an obstacle (row end inside it, no safe way)"),
      number("tracking_reserve", &A::tracking_reserve, 0.25, Limits::closed(0.0, 0.9), "",
             "share of max_yaw_rate and max_lateral_accel left to the controller"),
  });
  return table;
}

AvoidanceParams::AvoidanceParams() { avoidanceTable().applyDefaults(*this); }

std::string AvoidanceParams::validate() const {
  return firstError({avoidanceTable().checkRanges(*this, "field/avoidance/"),
                     checkNonNegative("footprint_radius", footprint_radius, "m")});
}

double AvoidanceParams::pathClearance(double influence) const {
  return std::max(footprint_radius + safety_margin, influence);
}

void Detour::lateral(double s, double& y, double& y1, double& y2, double& y3) const {
  y = y1 = y2 = y3 = 0.0;
  double x = s - begin;
  if (x <= 0.0 || x >= ramp_in + plateau + ramp_out) return;
  double f, f1, f2, f3;
  if (x < ramp_in) {
    cycloid(x / ramp_in, f, f1, f2, f3);
    y = offset * f;
    y1 = offset * f1 / ramp_in;
    y2 = offset * f2 / (ramp_in * ramp_in);
    y3 = offset * f3 / (ramp_in * ramp_in * ramp_in);
    return;
  }
  x -= ramp_in;
  if (x <= plateau) {
    y = offset;
    return;
  }
  x -= plateau;
  cycloid(1.0 - x / ramp_out, f, f1, f2, f3);  // mirrored: falls from offset to 0
  y = offset * f;
  y1 = -offset * f1 / ramp_out;
  y2 = offset * f2 / (ramp_out * ramp_out);
  y3 = -offset * f3 / (ramp_out * ramp_out * ramp_out);
}

std::vector<Obstacle> repulsionObstacles(const std::vector<Obstacle>& obstacles, const AvoidanceParams& params,
                                         double influence) {
  std::vector<Obstacle> out = obstacles;
  const double grow = params.pathClearance(influence) - influence;  // >= 0
  for (Obstacle& o : out) o.radius += grow;
  return out;
}

RowPlan planRow(int row, const Eigen::Vector2d& p0, double heading, double length, double row_speed,
                const std::vector<Obstacle>& obstacles, const AvoidanceParams& params, double influence,
                AvoidanceStatus& status) {
  RowPlan plan;
  plan.stop = length;
  const Eigen::Vector2d u = unitVector(heading), n(-u.y(), u.x());
  const double clearance = params.pathClearance(influence) + kPlanSlack;
  std::vector<Local> loc(obstacles.size());
  std::vector<std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const Eigen::Vector2d c(obstacles[i].x, obstacles[i].y);
    Local& o = loc[i];
    o.a = (c - p0).dot(u);
    o.l = (c - p0).dot(n);
    o.R = obstacles[i].radius + clearance;
    o.on_row = std::fabs(o.l) < o.R && o.a + o.R > 0.0 && o.a - o.R < length;
    if (o.on_row) groups.push_back({i});
  }
  if (groups.empty()) return plan;

  // Build a detour per group; merge groups whose detours overlap; add any obstacle a detour runs into;
  // repeat until nothing changes. Each round either merges two groups or adds an obstacle to one, so it
  // ends after at most 2 N rounds.
  auto build = [&](const std::vector<std::size_t>& g) {
    Detour d;
    d.row = row;
    d.obstacles = g;
    double h_left = -std::numeric_limits<double>::infinity(), h_right = h_left;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t i : g) {
      h_left = std::max(h_left, loc[i].l + loc[i].R);
      h_right = std::max(h_right, -loc[i].l + loc[i].R);
      lo = std::min(lo, loc[i].a - loc[i].R);
      hi = std::max(hi, loc[i].a + loc[i].R);
    }
    d.offset = h_left <= h_right ? h_left : -h_right;  // the narrower side; a tie goes left
    const double h = std::fabs(d.offset);
    const double ramp = std::sqrt(2.0 * M_PI * h / params.max_curvature);
    d.ramp_in = d.ramp_out = ramp;
    // The plateau spans the group's discs, [lo, hi]; then each end is pulled in as far as the ramp
    // still clears every disc of the group (bisection; clearance is monotone in the shift), so the
    // detour is no longer than it must be.
    auto clearOf = [&](const Detour& t, double from, double to) {
      const int samples = static_cast<int>(std::ceil((to - from) / kCheckStep)) + 1;
      for (int m = 0; m <= samples; ++m) {
        const double x = from + (to - from) * m / samples;
        double y, y1, y2, y3;
        t.lateral(x, y, y1, y2, y3);
        for (std::size_t i : g)
          if (std::hypot(x - loc[i].a, y - loc[i].l) < loc[i].R) return false;
      }
      return true;
    };
    double first_a = std::numeric_limits<double>::infinity(), last_a = -first_a;
    for (std::size_t i : g) {
      first_a = std::min(first_a, loc[i].a);
      last_a = std::max(last_a, loc[i].a);
    }
    double in_lo = 0.0, in_hi = std::max(0.0, first_a - lo);   // shift of the plateau start
    double out_lo = 0.0, out_hi = std::max(0.0, hi - last_a);  // shift of the plateau end
    for (int it = 0; it < 30; ++it) {
      Detour t = d;
      const double in_mid = 0.5 * (in_lo + in_hi);
      t.begin = lo + in_mid - ramp;
      t.plateau = hi - lo - in_mid;
      (clearOf(t, t.begin, t.begin + ramp + 1e-9) ? in_lo : in_hi) = in_mid;
      const double out_mid = 0.5 * (out_lo + out_hi);
      t.begin = lo - ramp;
      t.plateau = hi - lo - out_mid;
      (clearOf(t, t.begin + ramp + t.plateau, t.end()) ? out_lo : out_hi) = out_mid;
    }
    d.begin = lo + in_lo - ramp;
    d.plateau = hi - lo - in_lo - out_lo;
    return d;
  };
  std::vector<Detour> detours;
  const std::size_t max_rounds = 2 * obstacles.size() + 2;
  for (std::size_t round = 0;; ++round) {
    detours.clear();
    for (const auto& g : groups) detours.push_back(build(g));
    std::vector<std::size_t> order(detours.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::sort(order.begin(), order.end(),
              [&](std::size_t x, std::size_t y) { return detours[x].begin < detours[y].begin; });
    bool changed = false;
    for (std::size_t k = 0; k + 1 < order.size() && !changed; ++k) {
      if (detours[order[k + 1]].begin < detours[order[k]].end()) {  // overlapping: one group
        auto& a = groups[order[k]];
        auto& b = groups[order[k + 1]];
        a.insert(a.end(), b.begin(), b.end());
        groups.erase(groups.begin() + static_cast<long>(order[k + 1]));
        changed = true;
      }
    }
    for (std::size_t k = 0; k < detours.size() && !changed; ++k) {
      const Detour& d = detours[k];
      const int samples = static_cast<int>(std::ceil((d.end() - d.begin) / kCheckStep));
      for (int m = 0; m <= samples && !changed; ++m) {
        const double s = d.begin + (d.end() - d.begin) * m / samples;
        double y, y1, y2, y3;
        d.lateral(s, y, y1, y2, y3);
        for (std::size_t j = 0; j < loc.size(); ++j) {
          if (std::find(groups[k].begin(), groups[k].end(), j) != groups[k].end()) continue;
          if (std::hypot(s - loc[j].a, y - loc[j].l) < loc[j].R) {
            groups[k].push_back(j);
            changed = true;
            break;
          }
        }
      }
    }
    if (!changed) break;
    if (round > max_rounds) {
      status.code = AvoidanceStatus::Code::kNoSafeWay;
      status.reason = "row " + std::to_string(row) + ": no detour found around the obstacles near it";
      plan.cut = true;
      plan.stop = 0.0;
      return plan;
    }
  }
  std::sort(detours.begin(), detours.end(), [](const Detour& x, const Detour& y) { return x.begin < y.begin; });

  for (Detour& d : detours) {
    std::sort(d.obstacles.begin(), d.obstacles.end());
    // The nearest safe point on the row before this group: where the row line enters the first disc.
    double first_entry = std::numeric_limits<double>::infinity();
    for (std::size_t i : d.obstacles)
      if (loc[i].on_row) first_entry = std::min(first_entry, entry(loc[i]));
    const double stop = std::max(0.0, first_entry - params.stop_margin);
    auto cutHere = [&](AvoidanceStatus::Code code, const std::string& why) {
      plan.cut = true;
      plan.stop = stop;
      if (status.code == AvoidanceStatus::Code::kOk) {
        const Eigen::Vector2d q = p0 + stop * u;
        status.code = code;
        status.stop_point = q;
        status.reason =
            why + fmt("; stopping on the row at (%.2f, %.2f), %.2f m before the row end", q.x(), q.y(), length - stop);
      }
    };
    const double h = std::fabs(d.offset);
    const std::string who = "row " + std::to_string(row) + ", obstacle(s) " + indexList(d.obstacles);
    if (h > params.max_offset) {
      cutHere(AvoidanceStatus::Code::kNoSafeWay,
              who + fmt(": no safe way, passing needs a %.2f m sideways detour (avoidance/max_offset %.2f m)", h,
                        params.max_offset));
      break;
    }
    if (d.end() > length) {
      cutHere(
          AvoidanceStatus::Code::kStoppedShort,
          who + fmt(": the row end lies inside or %.2f m behind the inflated obstacles, too close to rejoin the row",
                    std::max(0.0, length - (d.begin + d.ramp_in + d.plateau))));
      break;
    }
    if (d.begin < 0.0) {  // the group is near the row start: a steeper up ramp, driven slower
      const double room = d.begin + d.ramp_in;
      if (room < kMinRamp) {
        cutHere(AvoidanceStatus::Code::kNoSafeWay, who + ": the row starts inside the inflated obstacles");
        plan.stop = 0.0;
        break;
      }
      d.begin = 0.0;
      d.ramp_in = room;
      status.within_bounds = false;
      if (status.bounds_note.empty())
        status.bounds_note = who + fmt(": too close to the row start for max_curvature (%.2f 1/m on the up ramp)",
                                       2.0 * M_PI * h / (room * room));
    }
    const double ramp = std::min(d.ramp_in, d.ramp_out);
    d.peak_curvature = 2.0 * M_PI * h / (ramp * ramp);
    const double slope = 2.0 * h / ramp;
    // Along-row speed sd: path speed sd sqrt(1 + y'^2) <= row_speed; omega = sd y''/(1 + y'^2) <= sd
    // kappa_peak; v omega = sd^2 y''/sqrt(1 + y'^2) <= sd^2 kappa_peak.
    const double use = 1.0 - params.tracking_reserve;
    d.speed = std::min({row_speed / std::sqrt(1.0 + slope * slope), use * params.max_yaw_rate / d.peak_curvature,
                        std::sqrt(use * params.max_lateral_accel / d.peak_curvature)});
    plan.detours.push_back(d);
  }
  status.detours += plan.detours.size();
  return plan;
}

}  // namespace core
}  // namespace sowing_robot
