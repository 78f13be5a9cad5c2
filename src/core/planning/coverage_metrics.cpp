#include "sowing_robot/core/planning/coverage_metrics.h"

// Boost.Geometry's buffer and envelope code, inlined here, trips GCC 12's -Wmaybe-uninitialized on a box it fills
// before reading (a false positive that -Werror would turn into a failed build).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <algorithm>
#include <stdexcept>

#include "sowing_robot/core/planning/polygon_ops.h"

namespace sowing_robot {
namespace core {

namespace bg = boost::geometry;

CoverageFigures coverageFigures(const FieldBoundary& field, const CoveragePlan& plan) {
  CoverageFigures f;
  const double w = plan.working_width;
  const geo::MultiPolygon workable = geo::workable(field);
  f.field_area = bg::area(geo::outerPolygon(field));
  f.workable_area = bg::area(workable);

  // What the tool sweeps: each swath from its start to its end, each headland loop closed. Not the route's tool-down
  // stretches: those are the axle's, which on a swath run run_out ahead of the tool point (CoverageParams::run_out).
  geo::MultiLine sown, swaths;
  for (const Ring& ring : plan.headland_rings) {
    geo::Line loop;
    for (const Eigen::Vector2d& q : ring) loop.push_back(geo::toPoint(q));
    if (!ring.empty()) loop.push_back(geo::toPoint(ring.front()));
    sown.push_back(loop);
  }
  for (const Swath& s : plan.swaths) swaths.push_back(geo::Line{geo::toPoint(s.a), geo::toPoint(s.b)});
  sown.insert(sown.begin(), swaths.begin(), swaths.end());

  const geo::MultiPolygon all = geo::strip(sown, w);
  double summed = 0.0;
  for (const geo::Line& l : sown) summed += bg::area(geo::strip(l, w));
  const double union_area = bg::area(all);
  // Covered = workable minus what the strips leave of it: Boost's union of strips that touch side by side (one
  // width apart) can come out with self-intersections, on which an intersection loses whole strips (13 % on the
  // 10 ha field) while the difference stays within the union's area.
  geo::MultiPolygon left;
  bg::difference(workable, all, left);
  f.covered_area = std::max(0.0, f.workable_area - bg::area(left));
  f.covered_share = f.workable_area > 0.0 ? f.covered_area / f.workable_area : 0.0;
  f.missed_share = f.workable_area > 0.0 ? std::max(0.0, f.workable_area - f.covered_area) / f.workable_area : 0.0;
  f.overlap_share = union_area > 0.0 ? std::max(0.0, summed - union_area) / union_area : 0.0;
  f.outside_share = union_area > 0.0 ? std::max(0.0, union_area - f.covered_area) / union_area : 0.0;

  // The rows' strips, measured as the covered area is (a difference).
  const std::vector<RowSegment> rows = plan.rows();
  if (!rows.empty()) {
    const std::size_t per_pass = plan.swaths.empty() ? 1 : std::max<std::size_t>(1, plan.swaths.front().rows.size());
    geo::MultiLine lines;
    for (const RowSegment& r : rows) lines.push_back(geo::Line{geo::toPoint(r.a), geo::toPoint(r.b)});
    geo::MultiPolygon rows_left;
    bg::difference(workable, geo::strip(lines, w / static_cast<double>(per_pass)), rows_left);
    f.row_area = std::max(0.0, f.workable_area - bg::area(rows_left));
  }

  // The inner field's share under the swaths' strips.
  geo::MultiPolygon inner_field;
  {
    // Rebuild it as polygons: the rings with positive orientation as Boost expects are outer ones.
    geo::MultiPolygon outers, holes;
    for (const Ring& r : plan.inner_field) {
      geo::Polygon p;
      for (const Eigen::Vector2d& q : r) p.outer().push_back(geo::toPoint(q));
      if (!r.empty()) p.outer().push_back(geo::toPoint(r.front()));
      const bool is_outer = bg::area(p) > 0.0;  // Boost's clockwise outer rings have positive area
      bg::correct(p);
      (is_outer ? outers : holes).push_back(p);
    }
    bg::difference(outers, holes, inner_field);
  }
  f.inner_area = bg::area(inner_field);
  geo::MultiPolygon inner_left;
  bg::difference(inner_field, geo::strip(swaths, w), inner_left);
  f.covered_inner_share = f.inner_area > 0.0 ? std::max(0.0, f.inner_area - bg::area(inner_left)) / f.inner_area : 0.0;

  f.swaths = static_cast<int>(plan.swaths.size());
  f.path_length = plan.path_length;
  f.turn_length = plan.turn_length;
  return f;
}

double areaSown(const std::vector<Seed>& seeds, double width, double spacing) {
  if (!(width > 0.0) || !(spacing > 0.0)) throw std::invalid_argument("areaSown: width and spacing must be > 0");
  std::vector<const Seed*> order;
  for (const Seed& s : seeds) order.push_back(&s);
  std::stable_sort(order.begin(), order.end(), [](const Seed* a, const Seed* b) { return a->t < b->t; });
  geo::MultiLine runs;
  geo::Line run;
  const Seed* prev = nullptr;
  for (const Seed* s : order) {
    const bool joins = prev && prev->row == s->row && (s->truth - prev->truth).norm() < 1.5 * spacing;
    if (!joins) {
      if (run.size() >= 2) runs.push_back(run);
      run.clear();
    }
    run.push_back(geo::toPoint(s->truth));
    prev = s;
  }
  if (run.size() >= 2) runs.push_back(run);
  return runs.empty() ? 0.0 : bg::area(geo::strip(runs, width));
}

}  // namespace core
}  // namespace sowing_robot
