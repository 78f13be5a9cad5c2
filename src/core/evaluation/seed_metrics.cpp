#include "sowing_robot/core/evaluation/seed_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace sowing_robot {
namespace core {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using Interval = std::pair<double, double>;

/// Sorted, merged, clipped to [0, length].
std::vector<Interval> mergeIntervals(std::vector<Interval> v, double length) {
  std::sort(v.begin(), v.end());
  std::vector<Interval> out;
  for (Interval i : v) {
    i.first = std::max(i.first, 0.0);
    i.second = std::min(i.second, length);
    if (!(i.second > i.first)) continue;
    if (!out.empty() && i.first <= out.back().second)
      out.back().second = std::max(out.back().second, i.second);
    else
      out.push_back(i);
  }
  return out;
}

double totalLength(const std::vector<Interval>& v) {
  double sum = 0.0;
  for (const Interval& i : v) sum += i.second - i.first;
  return sum;
}

/// Length of the overlap of two merged interval lists.
double overlap(const std::vector<Interval>& a, const std::vector<Interval>& b) {
  double sum = 0.0;
  for (const Interval& x : a)
    for (const Interval& y : b) sum += std::max(0.0, std::min(x.second, y.second) - std::max(x.first, y.first));
  return sum;
}

/// a less the stretches of b (both merged).
std::vector<Interval> subtract(const std::vector<Interval>& a, const std::vector<Interval>& b) {
  std::vector<Interval> out;
  for (Interval x : a) {
    for (const Interval& y : b) {
      if (y.second <= x.first || y.first >= x.second) continue;
      if (y.first > x.first) out.push_back({x.first, y.first});
      x.first = std::max(x.first, y.second);
      if (!(x.second > x.first)) break;
    }
    if (x.second > x.first) out.push_back(x);
  }
  return out;
}

/// The merged stretches of `row` the tool point passed over in `state`.
std::vector<Interval> passedIn(const std::vector<RowPass>& passes, std::size_t row, DrillState state, double length) {
  std::vector<Interval> v;
  for (const RowPass& p : passes)
    if (p.row == static_cast<int>(row) && p.state == state) v.push_back({p.from, p.to});
  return mergeIntervals(std::move(v), length);
}

/// The stretches of row r (along-row coordinate in [0, length]) that an obstacle blocks (SeedDrill::blockedRadius).
std::vector<Interval> obstacleStretches(const RowSegment& r, const SeedDrill& plan) {
  const Eigen::Vector2d d = r.b - r.a;
  const double length = d.norm();
  std::vector<Interval> out;
  if (!(length > 0.0)) return out;
  const Eigen::Vector2d u = d / length;
  for (const Obstacle& o : plan.obstacles()) {
    const Eigen::Vector2d c(o.x, o.y);
    const double along = (c - r.a).dot(u);
    const double across = (c - r.a - along * u).norm();
    const double radius = plan.blockedRadius(o);
    if (across >= radius) continue;
    const double half = std::sqrt(radius * radius - across * across);
    out.push_back({along - half, along + half});
  }
  return mergeIntervals(std::move(out), length);
}

/// True when [a, b] meets one of v's intervals.
bool meets(const std::vector<Interval>& v, double a, double b) {
  for (const Interval& i : v)
    if (b > i.first && a < i.second) return true;
  return false;
}

/// Nearest-rank p95 of v (sorted in place), NaN when empty.
double p95(std::vector<double>& v) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(v.size()))) - 1];
}

double rms(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  double sq = 0.0;
  for (double x : v) sq += x * x;
  return std::sqrt(sq / static_cast<double>(v.size()));
}

}  // namespace

SeedFigures::SeedFigures()
    : sown_share(kNaN),
      worst_row_share(kNaN),
      detour_sown_share(kNaN),
      multiples(kNaN),
      misses(kNaN),
      quality_of_feed(kNaN),
      precision(kNaN),
      lateral_rms(kNaN),
      lateral_p95(kNaN),
      lateral_max(kNaN),
      depth_outside(kNaN),
      map_error_rms(kNaN),
      map_error_p95(kNaN),
      unsown_start(kNaN),
      unsown_end(kNaN),
      unsown_mid(kNaN),
      unsown_held_up(kNaN),
      unsown_not_engaged(kNaN),
      unsown_not_asked(kNaN) {}

SeedFigures seedFigures(const std::vector<Seed>& seeds, const SeedDrill& plan, const std::vector<RowPass>* passes) {
  SeedFigures f;
  f.seeds = seeds.size();
  const double spacing = plan.params().spacing;
  const std::vector<RowSegment>& rows = plan.rows();
  // Each row's seeds by their position along it.
  std::vector<std::vector<double>> along(rows.size());
  std::vector<double> lateral;
  for (const Seed& s : seeds) {
    if (s.row < 0 || static_cast<std::size_t>(s.row) >= rows.size()) continue;
    const RowSegment& r = rows[static_cast<std::size_t>(s.row)];
    const Eigen::Vector2d d = r.b - r.a;
    const double length = d.norm();
    if (!(length > 0.0)) continue;
    const Eigen::Vector2d u = d / length;
    along[static_cast<std::size_t>(s.row)].push_back((s.truth - r.a).dot(u));
    if (!s.detour) lateral.push_back(std::fabs(u.x() * (s.truth - r.a).y() - u.y() * (s.truth - r.a).x()));
  }
  double length = 0.0, sown = 0.0, detour_length = 0.0, detour_sown = 0.0;
  double unsown_start = 0.0, unsown_end = 0.0, unsown_mid = 0.0, held_up = 0.0, not_engaged = 0.0, not_asked = 0.0;
  std::size_t spacings = 0, multiples = 0, misses = 0;
  std::vector<double> accepted;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double row_length = (rows[i].b - rows[i].a).norm();
    std::vector<double>& s = along[i];
    std::sort(s.begin(), s.end());
    std::vector<Interval> covered;
    for (std::size_t k = 0; k < s.size(); ++k) {
      covered.push_back({s[k] - 0.5 * spacing, s[k] + 0.5 * spacing});
      if (k + 1 < s.size() && s[k + 1] - s[k] <= kSownGap * spacing) covered.push_back({s[k], s[k + 1]});
    }
    covered = mergeIntervals(std::move(covered), row_length);
    const std::vector<Interval> detours = obstacleStretches(rows[i], plan);
    RowSowing rs;
    rs.detour_length = totalLength(detours);
    rs.length = row_length - rs.detour_length;
    rs.detour_sown = overlap(covered, detours);
    rs.sown = totalLength(covered) - rs.detour_sown;
    // Where the unsown length lies: before the first seed's stretch, after the last one's, between.
    const std::vector<Interval> unsown = subtract(subtract({{0.0, row_length}}, covered), detours);
    const double first = covered.empty() ? row_length : covered.front().first;
    const double last = covered.empty() ? row_length : covered.back().second;
    rs.unsown_start = overlap(unsown, {{0.0, first}});
    rs.unsown_end = overlap(unsown, {{last, row_length}});
    unsown_start += rs.unsown_start;
    unsown_end += rs.unsown_end;
    unsown_mid += std::max(0.0, totalLength(unsown) - rs.unsown_start - rs.unsown_end);
    if (passes != nullptr) {  // why, in this order: the hitch, the engage rule, the plan
      const std::vector<Interval> held = passedIn(*passes, i, DrillState::held_up, row_length);
      const std::vector<Interval> waiting = passedIn(*passes, i, DrillState::not_engaged, row_length);
      held_up += overlap(unsown, held);
      const std::vector<Interval> rest = subtract(unsown, held);
      not_engaged += overlap(rest, waiting);
      not_asked += overlap(subtract(rest, waiting), passedIn(*passes, i, DrillState::not_asked, row_length));
    }
    f.rows.push_back(rs);
    length += rs.length;
    sown += rs.sown;
    detour_length += rs.detour_length;
    detour_sown += rs.detour_sown;
    // ISO 7256-1 on the spacings clear of the obstacle stretches (one across them is the obstacle, not the meter).
    for (std::size_t k = 0; k + 1 < s.size(); ++k) {
      if (meets(detours, s[k], s[k + 1])) continue;
      const double x = s[k + 1] - s[k];
      ++spacings;
      if (x <= 0.5 * spacing)
        ++multiples;
      else if (x > 1.5 * spacing)
        ++misses;
      else
        accepted.push_back(x);
    }
  }
  if (!rows.empty()) {
    f.sown_share = length > 0.0 ? sown / length : 1.0;
    f.worst_row_share = 1.0;
    for (const RowSowing& r : f.rows) f.worst_row_share = std::min(f.worst_row_share, r.share());
    if (detour_length > 0.0) f.detour_sown_share = detour_sown / detour_length;
    f.unsown_start = unsown_start;
    f.unsown_end = unsown_end;
    f.unsown_mid = unsown_mid;
    if (passes != nullptr) {
      f.unsown_held_up = held_up;
      f.unsown_not_engaged = not_engaged;
      f.unsown_not_asked = not_asked;
    }
  }
  if (spacings > 0) {
    f.multiples = 100.0 * static_cast<double>(multiples) / static_cast<double>(spacings);
    f.misses = 100.0 * static_cast<double>(misses) / static_cast<double>(spacings);
    f.quality_of_feed = 100.0 - f.multiples - f.misses;
    if (accepted.size() > 1) {
      double mean = 0.0;
      for (double x : accepted) mean += x;
      mean /= static_cast<double>(accepted.size());
      double sq = 0.0;
      for (double x : accepted) sq += (x - mean) * (x - mean);
      f.precision = 100.0 * std::sqrt(sq / static_cast<double>(accepted.size() - 1)) / spacing;
    }
  }
  if (!lateral.empty()) {
    f.lateral_rms = rms(lateral);
    f.lateral_max = *std::max_element(lateral.begin(), lateral.end());
    f.lateral_p95 = p95(lateral);
  }
  if (!seeds.empty()) {
    const SeedingParams& p = plan.params();
    std::size_t outside = 0;
    std::vector<double> map;
    for (const Seed& s : seeds) {
      if (s.depth < p.depth_min - 1e-12 || s.depth > p.depth_max + 1e-12) ++outside;
      map.push_back((s.believed - s.truth).norm());
    }
    f.depth_outside = static_cast<double>(outside) / static_cast<double>(seeds.size());
    f.map_error_rms = rms(map);
    f.map_error_p95 = p95(map);
  }
  return f;
}

}  // namespace core
}  // namespace sowing_robot
