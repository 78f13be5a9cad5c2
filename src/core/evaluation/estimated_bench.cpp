#include "sowing_robot/core/evaluation/estimated_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>

#include "sowing_robot/core/evaluation/bench_row.h"
#include "sowing_robot/core/planning/field_soil.h"
#include "sowing_robot/core/planning/seeding.h"

namespace sowing_robot {
namespace core {

const std::vector<std::string>& availableModels() {
  static const std::vector<std::string> models{"wet_soil", "estimated_pose"};
  return models;
}

namespace {

/// benchmark.cpp's measure() over runClosedLoop: the same figures (RowMeter; a truth-fed run without
/// traction gives its row bit for bit: test_estimated_run), plus the loop's own.
RunRow measureEstimated(const Scenario& sc, const LoopConfig& cfg, ReferenceSource& reference,
                        const MonteCarloSpec& spec, const RunDraw& draw, const RunExtras& extras) {
  RunRow row;
  row.draw = draw;
  RowMeter meter(row, sc, spec, extras);
  const LoopResult er = runClosedLoop(sc, cfg, reference, true, [&](const EstimatedSample& es) { meter.add(es); });
  meter.finish(er.run);
  // No traction is why the run ended early: it comes before a performance verdict (and the finish check,
  // which leaves it be), after a divergence or a contact.
  if (er.no_traction.detected && (row.failure.empty() || performanceFailure(row.failure))) {
    row.failure = er.no_traction.text();
    row.success = false;
  }
  row.realism = true;
  row.max_slip = er.max_abs_slip;
  row.high_slip_share = er.run.periods > 0
                            ? er.high_slip_time / (1e-9 * static_cast<double>(er.run.periods * sc.control_period_ns))
                            : 0.0;
  row.tool_down_time = er.tool_down_time;
  row.fed_error_rms = er.fed_error_rms;
  row.fed_error_max = er.fed_error_max;
  row.odometry_error_max = er.odometry_error_max;
  row.fixes_applied = er.fixes.applied;
  row.fixes_refused = er.fixes.refused();
  row.unsown_distance = er.unsown_distance;
  row.seeds_unsown = er.unsown_distance / cfg.seeding.spacing;
  // The sown rule's slip bound, once the rest of the run has passed (the traction plant only: NaN otherwise).
  if (row.failure.empty() && spec.rule == SuccessRule::sown && extras.seed_plan != nullptr &&
      row.high_slip_share > spec.max_high_slip_share) {
    row.failure = "slip";
    row.success = false;
  }
  return row;
}

}  // namespace

std::string estimatedBenchCheck(const BenchScenario& b) {
  const auto& available = availableModels();
  for (const std::string& m : b.requires_models) {
    if (std::find(available.begin(), available.end(), m) == available.end())
      return "scenario " + b.name + " needs the " + m + " model, which is not available";
    if (m == "wet_soil" && !(b.realism && b.realism->traction))
      return "scenario " + b.name + " requires wet_soil but its traction is not enabled (traction/enabled: true)";
    if (m == "estimated_pose" && !(b.realism && b.realism->feedback != Feedback::ground_truth))
      return "scenario " + b.name + " requires estimated_pose but its feedback is ground_truth (feedback: fused)";
  }
  return b.realism ? b.realism->validate() : "";
}

RunRow estimatedBenchRow(const BenchScenario& bench, std::int64_t index) {
  if (!bench.realism) throw std::invalid_argument("estimatedBenchRow: scenario " + bench.name + " has no realism");
  const MonteCarloSpec& spec = bench.spec;
  const RunDraw draw = drawRun(spec, bench.base, index);
  Scenario sc = applyDraw(bench.base, spec, draw);
  LoopConfig cfg = *bench.realism;
  cfg.sensors.seed = draw.sensor_seed;
  RunExtras extras;
  extras.series_every = seriesEvery(bench);
  if (bench.track == TrackKind::line) {
    // The tool works the whole line (with traction and a draft, the draft acts once it is down on it).
    cfg.tool_rows = {RowSegment{Eigen::Vector2d(bench.line_x0, bench.line_y),
                                Eigen::Vector2d(bench.line_x0 + bench.line_v_r * sc.duration, bench.line_y)}};
    LineReference reference(bench.line_v_r, bench.line_y, bench.line_x0);
    const SeedDrill plan = lineSeedPlan(bench);
    extras.seed_plan = &plan;
    extras.tool = cfg.tool;
    return measureEstimated(sc, cfg, reference, spec, draw, extras);
  }
  if (bench.track == TrackKind::sine) {
    SineReference reference(bench.sine);
    return measureEstimated(sc, cfg, reference, spec, draw, extras);
  }
  // Field: as runBenchmark's field runs (fieldRow), with the plant's tool rule on the field's rows (as
  // runField with traction).
  cfg.tool_rows = rowsOf(bench.field);
  cfg.tool_rows_open_ended = false;
  // The finish check reads the path's time: a robot the governor slowed for grip gets that time back.
  cfg.governed_time_back = true;
  return fieldRow(bench, sc, extras,
                  [&cfg, &spec, &draw](const Scenario& s, ReferenceSource& reference, const RunExtras& e) {
                    return measureEstimated(s, cfg, reference, spec, draw, e);
                  });
}

std::string estimatedReportLine(const std::vector<RunRow>& rows) {
  std::vector<double> slip, high, rms, mx, odo;
  long applied = 0, refused = 0;
  for (const RunRow& r : rows) {
    slip.push_back(r.max_slip);
    high.push_back(r.high_slip_share);
    rms.push_back(r.fed_error_rms);
    mx.push_back(r.fed_error_max);
    odo.push_back(r.odometry_error_max);
    applied += r.fixes_applied;
    refused += r.fixes_refused;
  }
  const Statistic s = statistic(slip), e = statistic(rms), m = statistic(mx), o = statistic(odo);
  const Statistic h = statistic(high);
  // The slip target (docs/robust_tuning.md): within twice the peak's slip for 95 % of the run.
  const auto within = std::count_if(high.begin(), high.end(), [](double share) { return share <= 0.05; });
  std::string out =
      "max |slip ratio| mean " + shortNumber(s.mean) + ", worst " + shortNumber(s.worst) +
      "; share of the run above twice the friction peak's slip mean " + shortNumber(h.mean) + ", worst " +
      shortNumber(h.worst) + ", at most 0.05 in " + std::to_string(within) + " of " + std::to_string(rows.size()) +
      " runs; fed-pose error against the truth: RMS mean " + shortNumber(e.mean) + " m (p95 " + shortNumber(e.p95) +
      ", worst " + shortNumber(e.worst) + "), max mean " + shortNumber(m.mean) + " m (worst " + shortNumber(m.worst) +
      "); encoder odometry's largest error mean " + shortNumber(o.mean) + " m (worst " + shortNumber(o.worst) + ")";
  if (applied + refused > 0)
    out += "; fixes applied " + std::to_string(applied) + ", refused " + std::to_string(refused);
  std::vector<double> unsown, seeds;
  for (const RunRow& r : rows)
    if (r.unsown_distance > 0.0) {
      unsown.push_back(r.unsown_distance);
      seeds.push_back(r.seeds_unsown);
    }
  if (!unsown.empty()) {  // the hitch control raised the tool on slip in these runs
    const Statistic u = statistic(unsown), n = statistic(seeds);
    out += "; tool raised on slip (hitch control) in " + std::to_string(unsown.size()) + " of " +
           std::to_string(rows.size()) + " runs: row left unsown mean " + shortNumber(u.mean) + " m (worst " +
           shortNumber(u.worst) + " m), seeds lost mean " + shortNumber(n.mean) + " (worst " + shortNumber(n.worst) +
           ")";
  }
  return out + "\n\n";
}

std::string describeRealism(const BenchScenario& b) {
  if (!b.realism) return "";
  const LoopConfig& c = *b.realism;
  std::string out = "  Plant: ";
  if (c.traction) {
    out += "traction (mu_peak " + shortNumber(c.traction->mu_peak) + ", mu_slide " + shortNumber(c.traction->mu_slide) +
           ", rolling resistance " + shortNumber(c.traction->rolling_resistance) + ", draft " +
           shortNumber(c.traction->draft_force) + " N while the tool is down), " + std::to_string(c.patches.size()) +
           " soil patch(es)";
    for (const SoilPatch& p : c.patches) out += " [mu_peak " + shortNumber(p.mu_peak) + "]";
    // The grip budget of each soil (FIELD.md): what the drive wheels can push against what it takes.
    const auto budget = [&](const char* what, double mu_peak, double mu_slide, double rr) {
      const GripBudget g = gripBudget(b.base.robot, 1.0, *c.traction, mu_peak, mu_slide, rr);
      return std::string(what) + " peak " + shortNumber(g.peak) + " N, slide " + shortNumber(g.slide) + " N, needed " +
             shortNumber(g.needed) + " N (margin " + shortNumber(g.margin()) + " N)";
    };
    out += "; grip budget at the nominal mass: field" +
           budget("", c.traction->mu_peak, c.traction->mu_slide, c.traction->rolling_resistance);
    for (std::size_t i = 0; i < c.patches.size(); ++i)
      out += "; patch " + std::to_string(i) +
             budget("", c.patches[i].mu_peak, c.patches[i].mu_slide, c.patches[i].rolling_resistance);
    // The field check: can each soil pull the drill at the band's shallowest depth (the least a depth control
    // can ask), at the nominal speed? One that cannot is where the tool must be lifted.
    for (const DraftCheck& d : checkFieldDraft(b.base.robot, 1.0, *c.traction, c.patches, c.seeding.depth_min))
      out += "; field check: " + d.why;
    const std::string overlap = patchOverlapNote(c.patches);
    if (!overlap.empty()) out += "; field check: " + overlap;
    if (b.track == TrackKind::field) {
      const std::string outside = patchesOutsideField(b.field, c.patches);
      if (!outside.empty()) out += "; field check: WARNING " + outside;
    }
  } else {
    out += "no slip";
  }
  out +=
      std::string("; motors ") +
      (c.motor.enabled ? "on (current limit " + shortNumber(c.motor.current_limit) + " N·m, no-load " +
                             shortNumber(c.motor.no_load_speed) + " rad/s)"
                       : "off") +
      ", command limits " +
      (c.limits.enabled ? "on (v " + shortNumber(c.limits.max_v) + " m/s, " + shortNumber(c.limits.max_acceleration) +
                              " m/s^2; omega " + shortNumber(c.limits.max_omega) + " rad/s, " +
                              shortNumber(c.limits.max_angular_accel) + " rad/s^2)"
                        : "off") +
      ", traction control " + (c.traction_control.enabled ? "on" : "off") + ", speed governor " +
      (c.speed_governor.enabled ? "on" : "off") + ", hitch control " +
      (c.hitch_control.enabled
           ? (c.hitch_control.depth_control
                  ? "on with depth control (" + shortNumber(100.0 * c.hitch_control.depth_nominal) + " cm, down to " +
                        shortNumber(100.0 * c.hitch_control.depth_shallowest) + " cm before lifting)"
                  : "on")
           : "off");
  out += "; feedback " + std::string(feedbackName(c.feedback)) +
         " (sensors: " + std::to_string(c.sensors.encoder.ticks_per_turn) + " ticks/turn, gyro noise " +
         shortNumber(c.sensors.imu.noise) + " rad/s bias " + shortNumber(c.sensors.imu.bias) + " rad/s, fix " +
         shortNumber(c.sensors.fix.rate) + " Hz sigma " + shortNumber(c.sensors.fix.sigma) + " m latency " +
         shortNumber(c.sensors.fix.latency) + " s; their seed drawn per run)";
  if (c.feedback == Feedback::fused)
    out += std::string("; EKF with the bias state ") + (c.estimator.estimate_bias ? "on" : "off") + ", fix delay " +
           shortNumber(c.estimator.fix_delay) + " s, gate " + shortNumber(c.estimator.gate);
  return out + "; scored on the truth.\n";
}

}  // namespace core
}  // namespace sowing_robot
