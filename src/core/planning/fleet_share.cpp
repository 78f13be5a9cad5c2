#include "sowing_robot/core/planning/fleet_share.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sowing_robot {
namespace core {

const ParamTable<FleetShareParams>& fleetShareTable() {
  using S = FleetShareParams;
  static const ParamTable<S> table = [] {
    ParamTable<S> t({
        integer("fleet/robots", &S::robots, 0, Limits::closed(0, 8), "",
                "type coverage: robots sharing the field (fleet.launch field_file:=); each plans the same split "
                "(core/planning/fleet_split.h) and drives its own share. 0: one robot on the whole route, from the "
                "route's start"),
        integer("fleet/index", &S::index, 0, Limits::closed(0, 7), "", "this robot's index in the fleet (< robots)"),
        number("fleet/start_x", &S::start_x, 5.0, Limits::any(), "m",
               "robot 0's start this far east of the field's south-west corner (its bounding box's)"),
        number("fleet/start_spacing", &S::start_spacing, 5.0, Limits::positive(), "m",
               "the start poses side by side, this far apart eastwards, facing north"),
        number("fleet/start_back", &S::start_back, 5.0, Limits::any(), "m",
               "the start poses this far south of the field's bounding box"),
        flag("fleet/keep_apart", &S::keep_apart, true,
             "plan start waits so that no two robots come closer than fleet/safety_distance or drive in the same "
             "headland stretch at once (keepApart); false: every robot leaves at once"),
    });
    ParamTable<FleetParams> k({
        number("fleet/safety_distance", &FleetParams::safety_distance, 2.0, Limits::positive(), "m",
               "keepApart: no two planned robots closer than this"),
        number("fleet/stretch_length", &FleetParams::stretch_length, 10.0, Limits::positive(), "m",
               "keepApart: side of a headland stretch"),
        number("fleet/time_step", &FleetParams::time_step, 0.25, Limits::positive(), "s",
               "keepApart: sampling of the timed paths"),
        number("fleet/wait_step", &FleetParams::wait_step, 5.0, Limits::positive(), "s",
               "keepApart: planned waits are multiples of it"),
        number("fleet/max_wait", &FleetParams::max_wait, 3600.0, Limits::nonNegative(), "s",
               "keepApart: the longest wait tried for one robot"),
    });
    t.nest("", &S::plan, k);
    t.add(flag("fleet/yield", &S::yield, false,
               "run-time yield: every fleet/decision_period of simulated time the reference waits for fleet_monitor's "
               "verdict (fleet/verdict) on that stamp and holds (slows to a stop, Reference stop) while told to"));
    t.add(number("fleet/decision_period", &S::decision_period, 0.1, Limits::closed(1e-3, 10.0), "s",
                 "simulated time between the fleet's verdicts (fleet_monitor's decision_period must be the same)"));
    t.add(number("fleet/ramp_time", &S::ramp_time, 2.0, Limits::closed(1e-3, 60.0), "s",
                 "a hold slows the reference's time from full rate to 0 in this time (and back when released)"));
    return t;
  }();
  return table;
}

std::string FleetShareParams::validate() const {
  std::string e = fleetShareTable().checkRanges(*this);
  if (e.empty() && robots > 0 && index >= robots) e = "fleet/index must be < fleet/robots";
  if (e.empty() && robots == 0 && yield) e = "fleet/yield needs fleet/robots > 0";
  if (e.empty()) e = plan.validate();
  return e;
}

std::vector<Pose2D> fleetStarts(const Ring& outer, const FleetShareParams& params) {
  if (outer.empty()) throw std::invalid_argument("fleetStarts: the field has no boundary");
  double min_x = outer.front().x(), min_y = outer.front().y();
  for (const Eigen::Vector2d& p : outer) {
    min_x = std::min(min_x, p.x());
    min_y = std::min(min_y, p.y());
  }
  std::vector<Pose2D> starts;
  for (int i = 0; i < std::max(1, params.robots); ++i)
    starts.push_back({min_x + params.start_x + params.start_spacing * i, min_y - params.start_back, M_PI / 2});
  return starts;
}

Pose2D routeStart(const CoveragePlan& plan) {
  const auto& p = plan.route.points;
  if (p.empty()) throw std::invalid_argument("routeStart: the plan has no route");
  for (std::size_t i = 1; i < p.size(); ++i)
    if ((p[i] - p[0]).norm() > 1e-9) return {p[0].x(), p[0].y(), std::atan2(p[i].y() - p[0].y(), p[i].x() - p[0].x())};
  return {p[0].x(), p[0].y(), 0.0};
}

FleetShare planFleetShare(const CoveragePlan& plan, const FleetShareParams& params, const CoverageParams& coverage,
                          const PathParams& follower) {
  const std::string e = params.validate();
  if (!e.empty()) throw std::invalid_argument(e);
  if (plan.field.empty()) throw std::invalid_argument("planFleetShare: the plan has no field");
  const int robots = std::max(1, params.robots);
  FleetShare out;
  out.fleet = splitCoverage(plan, robots, fleetStarts(plan.field.front(), params), coverage, follower);
  if (params.keep_apart && robots > 1) keepApart(out.fleet, plan, params.plan);
  for (std::size_t i = 0; i < out.fleet.shares.size(); ++i)
    if (out.fleet.shares[i].robot == params.index) out.share = static_cast<int>(i);
  return out;
}

FleetShareReference::FleetShareReference(std::unique_ptr<PathReference> source, double wait, double ramp_time)
    : source_(std::move(source)), wait_(wait), ramp_(ramp_time) {
  if (!source_) throw std::invalid_argument("FleetShareReference: no source");
  if (!(std::isfinite(wait) && wait >= 0.0)) throw std::invalid_argument("FleetShareReference: wait must be >= 0");
  if (!(std::isfinite(ramp_time) && ramp_time > 0.0))
    throw std::invalid_argument("FleetShareReference: ramp_time must be > 0");
}

std::unique_ptr<ReferenceSource> FleetShareReference::clone() const {
  return std::make_unique<FleetShareReference>(
      std::unique_ptr<PathReference>(static_cast<PathReference*>(source_->clone().release())), wait_, ramp_);
}

void FleetShareReference::restart() {
  source_->reset();
  hold_ = started_ = false;
  first_ = true;
  rate_ = 1.0;
  tau_ = last_t_ = lost_ = 0.0;
}

double FleetShareReference::progress() const {
  const double d = source_->plan().duration();
  return d > 0.0 ? std::min(1.0, tau_ / d) : 1.0;
}

Reference FleetShareReference::evaluate(double t) {
  const double dt = first_ ? 0.0 : std::max(0.0, t - last_t_);
  first_ = false;
  last_t_ = t;
  if (t < wait_) {  // the planned wait: standing at the start, held
    Reference r = source_->next(0.0);
    r.v = r.omega = r.v_dot = r.omega_dot = 0.0;
    r.stop = true;
    return r;
  }
  // The source's time: the time since the wait less what the holds took (so without a hold it is t - wait exactly).
  const double driven = started_ ? dt : 0.0;
  started_ = true;
  const double before = rate_;
  const double step = driven / ramp_;
  rate_ = hold_ ? std::max(0.0, rate_ - step) : std::min(1.0, rate_ + step);
  const double rate_dot = driven > 0.0 ? (rate_ - before) / driven : 0.0;
  lost_ += (1.0 - 0.5 * (before + rate_)) * driven;
  tau_ = std::max(tau_, t - wait_ - lost_);
  Reference r = source_->next(tau_);
  if (rate_ <= 0.0) {  // a hold: at rest where the time stopped, the hold path (docs/stops.md)
    r.v = r.omega = r.v_dot = r.omega_dot = 0.0;
    r.stop = true;
    return r;
  }
  // The time warped: d/dt of v(tau(t)) rate = v_dot rate^2 + v rate_dot.
  r.v_dot = r.v_dot * rate_ * rate_ + r.v * rate_dot;
  r.omega_dot = r.omega_dot * rate_ * rate_ + r.omega * rate_dot;
  r.v *= rate_;
  r.omega *= rate_;
  return r;
}

}  // namespace core
}  // namespace sowing_robot
