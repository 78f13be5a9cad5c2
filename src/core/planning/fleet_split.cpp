#include "sowing_robot/core/planning/fleet_split.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace sowing_robot {
namespace core {

std::string FleetParams::validate() const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(safety_distance)) return "fleet: safety_distance must be > 0";
  if (!positive(stretch_length)) return "fleet: stretch_length must be > 0";
  if (!positive(time_step)) return "fleet: time_step must be > 0";
  if (!positive(wait_step) || wait_step < time_step) return "fleet: wait_step must be >= time_step";
  if (!std::isfinite(max_wait) || max_wait < wait_step) return "fleet: max_wait must be >= wait_step";
  return "";
}

double FleetPlan::makespan() const {
  double m = 0.0;
  for (const RobotShare& s : shares) m = std::max(m, s.end());
  return m;
}

double toolArea(const CoveragePath& path, double working_width) {
  double length = 0.0;
  for (std::size_t k = 0; k + 1 < path.points.size() && k < path.tool_down.size(); ++k)
    if (path.tool_down[k]) length += (path.points[k + 1] - path.points[k]).norm();
  return working_width * length;
}

namespace {

double headingOf(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  return std::atan2(to.y() - from.y(), to.x() - from.x());
}

/// Appends `add` (which starts where `out` ends) to `out`.
void append(CoveragePath& out, const CoveragePath& add) {
  if (add.points.empty()) return;
  if (out.points.empty()) {
    out = add;
    return;
  }
  out.points.insert(out.points.end(), add.points.begin() + 1, add.points.end());
  out.tool_down.insert(out.tool_down.end(), add.tool_down.begin(), add.tool_down.end());
}

/// The pose at the end of a path, heading along its last segment.
Pose2D endPose(const CoveragePath& path, const Pose2D& fallback) {
  if (path.points.size() < 2) return fallback;
  const Eigen::Vector2d& a = path.points[path.points.size() - 2];
  const Eigen::Vector2d& b = path.points.back();
  return {b.x(), b.y(), headingOf(a, b)};
}

/// A headland ring driven as the planner drives it: from its first point round to it, tool down on its straight sides
/// (the plan's headland rows) and up on its corners (headlandSide).
CoveragePath loopPath(const Ring& ring, const CoverageParams& params) {
  CoveragePath p;
  p.points = ring;
  p.points.push_back(ring.front());
  for (std::size_t i = 0; i + 1 < p.points.size(); ++i)
    p.tool_down.push_back(headlandSide(p.points[i], p.points[i + 1], params));
  return p;
}

/// Where every swath is on the route: `first` the index of its start point a, `end` the index of the end of its
/// tool-down segment (b, or b + run_out along the swath: with coverage/run_out > 0 the route drives from a tool up
/// for run_out, then tool down to run_out past b).
struct SwathSpan {
  std::size_t first = 0, end = 0;
};
std::vector<SwathSpan> swathSegments(const CoveragePlan& plan) {
  std::vector<SwathSpan> out;
  const CoveragePath& r = plan.route;
  std::size_t k = 0;
  for (const Swath& s : plan.swaths) {
    const Eigen::Vector2d u = (s.b - s.a).normalized();
    // on the swath's line, at or beyond a along it
    const auto onLine = [&](const Eigen::Vector2d& p) {
      const Eigen::Vector2d d = p - s.a;
      return std::abs(u.x() * d.y() - u.y() * d.x()) < 1e-6 && u.dot(d) > -1e-6;
    };
    for (; k + 1 < r.points.size(); ++k)
      if ((r.points[k] - s.a).norm() < 1e-6) {
        std::size_t j = k;
        while (j + 1 < r.points.size() && !r.tool_down[j] && onLine(r.points[j + 1])) ++j;
        if (j + 1 < r.points.size() && r.tool_down[j] && onLine(r.points[j + 1]) &&
            u.dot(r.points[j + 1] - s.b) > -1e-6) {
          out.push_back({k, j + 1});
          k = j + 1;
          break;
        }
      }
    if (out.size() < static_cast<std::size_t>(&s - plan.swaths.data()) + 1)
      throw std::invalid_argument("splitCoverage: a swath is not on the plan's route");
  }
  return out;
}

/// Even-odd point in the union of rings (outer rings and holes alike).
bool insideRings(const std::vector<Ring>& rings, const Eigen::Vector2d& p) {
  bool in = false;
  for (const Ring& ring : rings) {
    if (ring.empty()) continue;
    for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
      const Eigen::Vector2d &a = ring[i], &b = ring[j];
      if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
        in = !in;
    }
  }
  return in;
}

/// Every share's timed path sampled on the check's clock: positions and headland stretches (-1: not in the
/// headland band).
struct Samples {
  double dt = 0.0;
  std::vector<std::vector<Eigen::Vector2d>> p;
  std::vector<std::vector<std::int64_t>> cell;

  Samples(const FleetPlan& fleet, const CoveragePlan& plan, const FleetParams& fp) : dt(fp.time_step) {
    const std::vector<Ring> outer = plan.field.empty() ? std::vector<Ring>{} : std::vector<Ring>{plan.field.front()};
    for (const RobotShare& s : fleet.shares) {
      const std::size_t n = static_cast<std::size_t>(std::ceil(s.timed.duration() / dt)) + 1;
      std::vector<Eigen::Vector2d> ps(n);
      std::vector<std::int64_t> cs(n, -1);
      for (std::size_t k = 0; k < n; ++k) {
        const Pose2D q = s.timed.at(k * dt).pose;
        ps[k] = {q.x, q.y};
        if (insideRings(outer, ps[k]) && !insideRings(plan.inner_field, ps[k])) {
          const auto cx = static_cast<std::int64_t>(std::floor(q.x / fp.stretch_length));
          const auto cy = static_cast<std::int64_t>(std::floor(q.y / fp.stretch_length));
          cs[k] = ((cx + (1 << 20)) << 21) + (cy + (1 << 20));
        }
      }
      p.push_back(std::move(ps));
      cell.push_back(std::move(cs));
    }
  }
  std::size_t length(int r, std::int64_t wait) const { return static_cast<std::size_t>(wait) + p[r].size(); }
};

/// Walks the samples of shares a and b with waits (in samples) wa, wb; calls f(n, distance, headland conflict)
/// for every sample where both are present (waiting or driving); f returns false to stop.
template <class F>
void walkPair(const Samples& s, int a, int b, std::int64_t wa, std::int64_t wb, double safety, F f) {
  const std::size_t end = std::min(s.length(a, wa), s.length(b, wb));
  for (std::size_t n = 0; n < end; ++n) {
    const bool da = static_cast<std::int64_t>(n) >= wa, db = static_cast<std::int64_t>(n) >= wb;
    const std::size_t ka = da ? n - wa : 0, kb = db ? n - wb : 0;
    const double d = (s.p[a][ka] - s.p[b][kb]).norm();
    const bool headland = da && db && s.cell[a][ka] >= 0 && s.cell[a][ka] == s.cell[b][kb];
    if (!f(n, d, d < safety || headland, headland && d >= safety, da && db)) return;
  }
}

std::vector<std::int64_t> waitSamples(const FleetPlan& fleet, double dt) {
  std::vector<std::int64_t> w;
  for (const RobotShare& s : fleet.shares) w.push_back(std::llround(s.wait / dt));
  return w;
}

FleetCheck checkSamples(const Samples& s, const std::vector<std::int64_t>& waits, const FleetParams& fp) {
  FleetCheck c;
  c.min_separation = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(s.p.size());
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      bool in = false;
      walkPair(s, a, b, waits[a], waits[b], fp.safety_distance,
               [&](std::size_t k, double d, bool conflict, bool headland, bool driving) {
                 if (driving && d < c.min_separation) {
                   c.min_separation = d;
                   c.min_separation_time = k * s.dt;
                   c.min_a = a;
                   c.min_b = b;
                 }
                 if (conflict && !in && c.conflicts.size() < 1000) c.conflicts.push_back({a, b, k * s.dt, d, headland});
                 in = conflict;
                 return true;
               });
    }
  std::sort(c.conflicts.begin(), c.conflicts.end(),
            [](const FleetConflict& x, const FleetConflict& y) { return x.time < y.time; });
  return c;
}

bool pairClear(const Samples& s, int a, int b, std::int64_t wa, std::int64_t wb, double safety) {
  bool clear = true;
  walkPair(s, a, b, wa, wb, safety, [&](std::size_t, double, bool conflict, bool, bool) {
    if (conflict) clear = false;
    return clear;
  });
  return clear;
}

}  // namespace

FleetPlan splitCoverage(const CoveragePlan& plan, int robots, const std::vector<Pose2D>& starts,
                        const CoverageParams& params, const PathParams& follower) {
  std::string e = params.validate();
  if (e.empty()) e = follower.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  const int n = static_cast<int>(plan.swaths.size());
  if (n == 0 || plan.route.points.size() < 2) throw std::invalid_argument("splitCoverage: the plan has no swaths");
  if (robots < 1 || robots > 8 || robots > n)
    throw std::invalid_argument("splitCoverage: robots must be in [1, 8] and at most the plan's " + std::to_string(n) +
                                " swaths");
  if (static_cast<int>(starts.size()) != robots)
    throw std::invalid_argument("splitCoverage: one start pose per robot is needed");
  for (const Pose2D& p : starts)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.theta))
      throw std::invalid_argument("splitCoverage: the start poses must be finite");

  // Costs: the whole route timed once; a swath is the time from its start to the next one's (its turn included).
  const CoveragePath& route = plan.route;
  const std::vector<SwathSpan> seg = swathSegments(plan);
  const PathPlan whole(
      route.points,
      PathStart{{route.points[0].x(), route.points[0].y(), headingOf(route.points[0], route.points[1])}, 0.0}, follower,
      route.tool_down);
  std::vector<double> along(route.points.size(), 0.0);  // the route's own arc length at every point
  for (std::size_t k = 1; k < route.points.size(); ++k)
    along[k] = along[k - 1] + (route.points[k] - route.points[k - 1]).norm();
  // The follower's arc length at a route point: projected within a window after the previous one (its fillets
  // cut the corners, so it runs a little short of the route's).
  double s_prev = 0.0;
  std::size_t k_prev = 0;
  auto followerS = [&](std::size_t k) {
    const double hi = s_prev + (along[k] - along[k_prev]) + 1.0;
    const double s = whole.project(route.points[k], s_prev, std::min(hi, whole.length())).s;
    s_prev = s;
    k_prev = k;
    return s;
  };
  std::vector<double> t_start(n + 1);
  for (int i = 0; i < n; ++i) t_start[i] = whole.timeAt(followerS(seg[i].first));
  t_start[n] = whole.timeAt(followerS(seg[n - 1].end));
  std::vector<double> prefix(n + 1, 0.0);  // swath time before swath i
  for (int i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + std::max(0.0, t_start[i + 1] - t_start[i]);

  const int loops = static_cast<int>(plan.headland_rings.size());
  std::vector<double> loop_cost(loops, 0.0);
  for (int j = 0; j < loops; ++j) {
    const CoveragePath lp = loopPath(plan.headland_rings[j], params);
    if (lp.points.size() < 3) continue;
    const PathPlan t(lp.points,
                     PathStart{{lp.points[0].x(), lp.points[0].y(), headingOf(lp.points[0], lp.points[1])}, 0.0},
                     follower, lp.tool_down);
    loop_cost[j] = t.duration();
  }

  // Loops to blocks (slots in route order): longest first to the least loaded.
  std::vector<std::vector<int>> slot_loops(robots);
  std::vector<double> loop_load(robots, 0.0);
  std::vector<int> by_cost(loops);
  std::iota(by_cost.begin(), by_cost.end(), 0);
  std::stable_sort(by_cost.begin(), by_cost.end(), [&](int x, int y) { return loop_cost[x] > loop_cost[y]; });
  for (const int j : by_cost) {
    const int s = static_cast<int>(std::min_element(loop_load.begin(), loop_load.end()) - loop_load.begin());
    slot_loops[s].push_back(j);
    loop_load[s] += loop_cost[j];
  }

  // Swath cuts evening out the totals (swaths + loops + approach), and the start poses assigned to the blocks with
  // the shortest longest approach; the approaches depend on the cuts, so a few rounds.
  std::vector<int> cut(robots + 1, 0);  // block s: swaths [cut[s], cut[s + 1])
  cut[robots] = n;
  std::vector<double> approach(robots, 0.0);
  std::vector<int> robot_of(robots);
  std::iota(robot_of.begin(), robot_of.end(), 0);
  for (int round = 0; round < 4; ++round) {
    const double total = prefix[n] + std::accumulate(loop_load.begin(), loop_load.end(), 0.0) +
                         std::accumulate(approach.begin(), approach.end(), 0.0);
    double want = 0.0;
    for (int s = 0; s + 1 < robots; ++s) {
      want += total / robots - loop_load[s] - approach[s];
      int best = cut[s] + 1;
      for (int b = cut[s] + 1; b <= n - (robots - 1 - s); ++b)
        if (std::fabs(prefix[b] - want) < std::fabs(prefix[best] - want)) best = b;
      cut[s + 1] = best;
    }
    std::vector<int> perm(robots);
    std::iota(perm.begin(), perm.end(), 0);
    double best_max = std::numeric_limits<double>::infinity(), best_sum = best_max;
    do {
      double mx = 0.0, sum = 0.0;
      for (int s = 0; s < robots; ++s) {
        const Pose2D& st = starts[perm[s]];
        const double d = (plan.swaths[cut[s]].a - Eigen::Vector2d(st.x, st.y)).norm();
        mx = std::max(mx, d);
        sum += d;
      }
      if (mx < best_max - 1e-9 || (mx < best_max + 1e-9 && sum < best_sum - 1e-9)) {
        best_max = mx;
        best_sum = sum;
        robot_of = perm;
      }
    } while (std::next_permutation(perm.begin(), perm.end()));
    for (int s = 0; s < robots; ++s) {
      const Pose2D& st = starts[robot_of[s]];
      approach[s] = (plan.swaths[cut[s]].a - Eigen::Vector2d(st.x, st.y)).norm() / follower.v_max;
    }
  }

  FleetPlan fleet;
  fleet.follower = follower;
  for (int s = 0; s < robots; ++s) {
    RobotShare sh;
    sh.robot = robot_of[s];
    sh.rank = s;
    sh.first_swath = cut[s];
    sh.swaths = cut[s + 1] - cut[s];
    sh.start = starts[sh.robot];
    sh.estimate = approach[s] + prefix[cut[s + 1]] - prefix[cut[s]] + loop_load[s];
    const Swath& first = plan.swaths[cut[s]];
    sh.path = coverageJoin(sh.start, {first.a.x(), first.a.y(), headingOf(first.a, first.b)}, params);
    CoveragePath block;
    block.points.assign(route.points.begin() + seg[cut[s]].first, route.points.begin() + seg[cut[s + 1] - 1].end + 1);
    block.tool_down.assign(route.tool_down.begin() + seg[cut[s]].first,
                           route.tool_down.begin() + seg[cut[s + 1] - 1].end);
    append(sh.path, block);
    // Its loops nearest entry first.
    std::vector<int> left = slot_loops[s];
    while (!left.empty()) {
      const Pose2D at = endPose(sh.path, sh.start);
      const auto next = std::min_element(left.begin(), left.end(), [&](int x, int y) {
        return (plan.headland_rings[x].front() - Eigen::Vector2d(at.x, at.y)).norm() <
               (plan.headland_rings[y].front() - Eigen::Vector2d(at.x, at.y)).norm();
      });
      const Ring& ring = plan.headland_rings[*next];
      if (ring.size() >= 3) {
        append(sh.path, coverageJoin(at, {ring[0].x(), ring[0].y(), headingOf(ring[0], ring[1])}, params));
        append(sh.path, loopPath(ring, params));
        sh.loops.push_back(*next);
      }
      left.erase(next);
    }
    sh.timed = PathPlan(sh.path.points, PathStart{sh.start, 0.0}, follower, sh.path.tool_down);
    fleet.shares.push_back(std::move(sh));
  }
  return fleet;
}

FleetCheck checkFleet(const FleetPlan& fleet, const CoveragePlan& plan, const FleetParams& params) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  const Samples s(fleet, plan, params);
  return checkSamples(s, waitSamples(fleet, params.time_step), params);
}

void keepApart(FleetPlan& fleet, const CoveragePlan& plan, const FleetParams& params) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  const Samples s(fleet, plan, params);
  const double dt = params.time_step;
  const std::int64_t step = std::max<std::int64_t>(1, std::llround(params.wait_step / dt));
  const std::int64_t most = std::llround(params.max_wait / dt);
  std::vector<std::int64_t> waits = waitSamples(fleet, dt);
  fleet.waits_added = 0;
  fleet.waits.clear();
  fleet.conflict_free = false;
  // Every round adds a wait to one robot, at most max_wait / wait_step per robot: the loop ends.
  const int rounds = static_cast<int>(fleet.shares.size()) * static_cast<int>(most / step + 1);
  for (int round = 0; round <= rounds; ++round) {
    fleet.check = checkSamples(s, waits, params);
    if (fleet.check.conflicts.empty()) {
      fleet.conflict_free = true;
      break;
    }
    const FleetConflict c = fleet.check.conflicts.front();
    // The lower-priority robot of the pair (later in route order: shares are in rank order) waits first.
    bool fixed = false;
    for (const int r : {c.b, c.a}) {
      const std::int64_t base = waits[r];
      for (std::int64_t w = base + step; w <= base + most && !fixed; w += step) {
        waits[r] = w;
        fixed = pairClear(s, c.a, c.b, waits[c.a], waits[c.b], params.safety_distance);
      }
      if (fixed) {
        fleet.waits.push_back({r, (waits[r] - base) * dt, c});
        break;
      }
      waits[r] = base;
    }
    if (!fixed) break;
    ++fleet.waits_added;
  }
  for (std::size_t r = 0; r < fleet.shares.size(); ++r) fleet.shares[r].wait = waits[r] * dt;
}

double driveEnergy(const PathPlan& timed, const DriveEnergyParams& p, double dt) {
  const double duration = timed.duration();
  if (!(duration > 0.0) || !(dt > 0.0)) return 0.0;
  const RobotParams& rb = p.robot;
  const int steps = static_cast<int>(std::ceil(duration / dt));
  const double h = duration / steps;
  const double roll = 0.5 * p.rolling_resistance * rb.m() * p.gravity;  // per wheel [N]
  const double loss = p.motor.no_load_speed / p.motor.stall_torque;     // R / k^2 at the wheel [rad/(s N m)]
  auto sign = [](double x) { return x > 1e-9 ? 1.0 : (x < -1e-9 ? -1.0 : 0.0); };
  double energy = 0.0;
  for (int k = 0; k < steps; ++k) {
    const Reference r = timed.at((k + 0.5) * h);
    const double w_right = (r.v + rb.L * r.omega) / rb.R, w_left = (r.v - rb.L * r.omega) / rb.R;
    const double fx = rb.m0() * r.v_dot + (r.tool_down ? p.draft_force * sign(r.v) : 0.0);
    const double mz = rb.I0() * r.omega_dot;
    const double tau_right = rb.R * (0.5 * fx + 0.5 * mz / rb.L + roll * sign(w_right));
    const double tau_left = rb.R * (0.5 * fx - 0.5 * mz / rb.L + roll * sign(w_left));
    for (const auto& [tau, w] : {std::pair{tau_right, w_right}, std::pair{tau_left, w_left}})
      energy += std::max(0.0, tau * w + tau * tau * loss) * h;
  }
  return energy;
}

FleetFigures fleetFigures(const FleetPlan& fleet, double working_width, const DriveEnergyParams& energy) {
  FleetFigures f;
  for (const RobotShare& s : fleet.shares) {
    RobotFigures r;
    r.area = toolArea(s.path, working_width);
    r.time = s.timed.duration();
    r.wait = s.wait;
    r.area_rate = r.time > 0.0 ? (r.area / 1e4) / (r.time / 3600.0) : 0.0;
    r.energy = driveEnergy(s.timed, energy) / 3600.0;
    r.energy_per_ha = r.area > 0.0 ? r.energy / (r.area / 1e4) : 0.0;
    f.area += r.area;
    f.energy += r.energy;
    f.robots.push_back(r);
  }
  f.makespan = fleet.makespan();
  f.area_rate = f.makespan > 0.0 ? (f.area / 1e4) / (f.makespan / 3600.0) : 0.0;
  f.energy_per_ha = f.area > 0.0 ? f.energy / (f.area / 1e4) : 0.0;
  return f;
}

}  // namespace core
}  // namespace sowing_robot
