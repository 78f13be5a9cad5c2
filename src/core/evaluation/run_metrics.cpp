#include "sowing_robot/core/evaluation/run_metrics.h"

#include <cstdio>
#include <type_traits>
#include <utility>

namespace sowing_robot {
namespace core {

namespace {

/// A double member of RunRow as a metric's get/set.
template <typename T>
void access(RunMetric& m, T RunRow::*field) {
  m.get = [field](const RunRow& r) { return static_cast<double>(r.*field); };
  if constexpr (std::is_same_v<T, bool>)
    m.set = [field](RunRow& r, double v) { r.*field = v != 0.0; };
  else
    m.set = [field](RunRow& r, double v) { r.*field = static_cast<T>(v); };
}

/// A member of RunRow's seed figures as a metric's get/set: a figure of the seed record (seed_figure).
template <typename T>
void access(RunMetric& m, T SeedFigures::*field) {
  m.get = [field](const RunRow& r) { return static_cast<double>(r.seed_figures.*field); };
  m.set = [field](RunRow& r, double v) { r.seed_figures.*field = static_cast<T>(v); };
  m.seed_figure = true;
}

/// The glyph of an axis in labels (the column suffix is axisName()).
const char* axisGlyph(int axis) {
  static const char* const glyphs[AXIS_COUNT] = {"x", "y", "θ"};
  return glyphs[axis];
}

std::vector<RunMetric> buildMetrics() {
  std::vector<RunMetric> out;
  // The tracking figures of each axis (axisFigures(): the same names as the metrics YAML), in runs.csv's
  // order: axis by axis, figure by figure. ITAE y, ISE y and IAE θ are plotted; ITAE y and IAE θ compared.
  for (int a = 0; a < AXIS_COUNT; ++a) {
    for (const AxisFigure& f : axisFigures()) {
      RunMetric m;
      m.name = std::string(f.name) + "_" + axisName(a);
      m.unit = axisUnit(f, a);
      m.label = std::string(f.label) + " " + axisGlyph(a);
      m.meaning = std::string(f.meaning) + " (" + axisName(a) + " error, world frame)";
      const auto member = f.member;
      m.get = [a, member](const RunRow& r) { return r.metrics[static_cast<std::size_t>(a)].*member; };
      m.set = [a, member](RunRow& r, double v) { r.metrics[static_cast<std::size_t>(a)].*member = v; };
      m.report_table = true;
      const std::string n = m.name;
      if (n == "itae_y") m.overview_column = 1;
      if (n == "itae_y" || n == "iae_theta") m.compared = true;
      if (n == "itae_y" || n == "ise_y" || n == "iae_theta") m.plots = kBoxPlot;
      if (n == "itae_y") m.plots |= kSweepPlot;
      out.push_back(std::move(m));
    }
  }
  const auto add = [&out](const char* name, const char* unit, const char* label, const char* meaning, auto field) {
    RunMetric m;
    m.name = name;
    m.unit = unit;
    m.label = label;
    m.meaning = meaning;
    access(m, field);
    out.push_back(std::move(m));
    return &out.back();
  };
  RunMetric* m = add("effort", "N²·m²·s", "effort", "integral of tau_r^2 + tau_l^2 over the run", &RunRow::effort);
  m->report_table = m->compared = true;
  m->overview_column = 3;
  m->plots = kBoxPlot;
  m = add("chattering", "N·m", "chattering", "total variation of the wheel torques, sum |delta tau_r| + |delta tau_l|",
          &RunRow::chattering);
  m->report_table = m->compared = true;
  m->overview_column = 4;
  m->plots = kBoxPlot;
  m = add("time_at_limit", "s", "time at limit", "time with either wheel torque clipped at its limit",
          &RunRow::time_at_limit);
  m->report_table = m->compared = true;
  m->overview_column = 5;
  m->aggregation = Aggregation::mean;
  m->plots = kBoxPlot;
  m = add("worst_cross_track", "m", "worst cross-track", "largest |cross-track error| from settle_time to the end",
          &RunRow::worst_cross_track);
  m->report_table = m->compared = true;
  m->overview_column = 2;
  m->overview_p95 = true;
  m->plots = kBoxPlot | kSweepPlot;
  m = add("final_cross_track", "m", "final cross-track", "|cross-track error| at the end of the run",
          &RunRow::final_cross_track);
  m->report_table = true;
  m->plots = kBoxPlot;
  m = add("contacts", "contacts", "contacts", "body contacts with obstacles (field tracks; 0 without obstacles)",
          &RunRow::contacts);
  m->format = MetricFormat::count;
  m->aggregation = Aggregation::mean;
  m = add("min_clearance", "m", "smallest body clearance",
          "smallest clearance of the body to an obstacle (NaN without obstacles)", &RunRow::min_clearance);
  m->better = Better::higher;
  m->plots = kBoxPlot;
  m = add("end_distance", "m", "end distance",
          "distance of the axle from the reference's last pose at the end (field tracks; NaN otherwise)",
          &RunRow::end_distance);
  m = add("diverged", "bool", "diverged", "the state left the finite range (its figures are then +inf)",
          &RunRow::diverged);
  m->format = MetricFormat::flag;
  m->aggregation = Aggregation::share;
  // The seed record (seed_metrics.h): tracks with rows to sow (NaN on the sine track).
  m = add("seeds", "seeds", "seeds", "seeds the drill placed", &SeedFigures::seeds);
  m->format = MetricFormat::count;
  m->aggregation = Aggregation::mean;
  m->better = Better::none;
  m = add("sown_share", "1", "sown share",
          "share of the rows sown outside obstacle stretches (consecutive seeds at most 1.5 spacings apart)",
          &SeedFigures::sown_share);
  m->report_table = m->compared = true;
  m->better = Better::higher;
  m->overview_column = 6;
  m->plots = kBoxPlot;
  m = add("worst_row_share", "1", "worst row sown", "sown share of the least-sown row", &SeedFigures::worst_row_share);
  m->better = Better::higher;
  m = add("detour_sown_share", "1", "detour sown", "sown share of the rows' obstacle stretches (NaN without)",
          &SeedFigures::detour_sown_share);
  m->better = Better::none;
  m = add("multiples_index", "%", "multiples D", "ISO 7256-1: share of seed spacings <= 0.5 x the set spacing",
          &SeedFigures::multiples);
  m = add("miss_index", "%", "misses M", "ISO 7256-1: share of seed spacings > 1.5 x the set spacing",
          &SeedFigures::misses);
  m = add("quality_of_feed", "%", "quality of feed", "ISO 7256-1: A = 100 - D - M", &SeedFigures::quality_of_feed);
  m->report_table = m->compared = true;
  m->better = Better::higher;
  m->overview_column = 7;
  m->plots = kBoxPlot;
  m = add("precision", "%", "precision C",
          "ISO 7256-1: standard deviation of the accepted spacings over the set spacing", &SeedFigures::precision);
  m->report_table = true;
  m = add("seed_lateral_rms", "m", "seed offset RMS", "RMS of the seeds' offset from their row's line (not in detours)",
          &SeedFigures::lateral_rms);
  m = add("seed_lateral_p95", "m", "seed offset p95", "p95 of the seeds' offset from their row's line (not in detours)",
          &SeedFigures::lateral_p95);
  m->report_table = m->compared = true;
  m->plots = kBoxPlot;
  m = add("seed_lateral_max", "m", "seed offset max", "largest offset of a seed from its row's line (not in detours)",
          &SeedFigures::lateral_max);
  m = add("depth_outside_share", "1", "depth outside band",
          "share of the seeds placed outside the agronomic depth band", &SeedFigures::depth_outside);
  m = add("map_error_rms", "m", "seed-map error RMS",
          "RMS of |believed - true seed position|: the fed pose's tool point against where the seed fell",
          &SeedFigures::map_error_rms);
  m->report_table = m->compared = true;
  m = add("map_error_p95", "m", "seed-map error p95", "p95 of |believed - true seed position|",
          &SeedFigures::map_error_p95);
  // Where the unsown length lies and why (seed_metrics.h): summed over the rows, outside obstacle stretches.
  m = add("unsown_row_start", "m", "unsown at row starts",
          "unsown row before each row's first seed (a seedless row: all)", &SeedFigures::unsown_start);
  m->report_table = true;
  m = add("unsown_row_end", "m", "unsown at row ends", "unsown row after each row's last seed",
          &SeedFigures::unsown_end);
  m->report_table = true;
  m = add("unsown_mid_row", "m", "unsown mid-row", "unsown row between seeds", &SeedFigures::unsown_mid);
  m->report_table = true;
  m = add("unsown_held_up", "m", "unsown, hitch up",
          "unsown row the tool point passed with the hitch holding the drill up", &SeedFigures::unsown_held_up);
  m = add("unsown_not_engaged", "m", "unsown, not engaged",
          "unsown row the tool point passed with the drill asked for but not yet lowered (engage_distance)",
          &SeedFigures::unsown_not_engaged);
  m = add("unsown_not_asked", "m", "unsown, not asked",
          "unsown row the tool point passed with the plan not asking for the drill (approach, turn)",
          &SeedFigures::unsown_not_asked);
  m = add("success", "bool", "success",
          "not diverged, no contact, finished, and the scenario's rule: sown (the seed record's figures within the "
          "scenario's bounds) or tracking (|cross-track| below the threshold from settle_time on)",
          &RunRow::success);
  m->format = MetricFormat::flag;
  m->aggregation = Aggregation::share;
  m->better = Better::higher;
  m->compared = true;
  // The realism block (estimated_bench.cpp's measureEstimated): scenarios with sensors, traction or an estimate.
  const auto realism = [&add](const char* name, const char* unit, const char* label, const char* meaning, auto field) {
    RunMetric* r = add(name, unit, label, meaning, field);
    r->group = MetricGroup::realism;
    r->aggregation = Aggregation::mean;
    return r;
  };
  realism("max_slip", "1", "max |slip ratio|", "largest |slip ratio| of either wheel (0 without traction)",
          &RunRow::max_slip);
  realism("tool_down_time", "s", "tool down time", "time the tool's draft acted", &RunRow::tool_down_time);
  realism("fed_error_rms", "m", "fed-pose error RMS",
          "RMS position error of the pose fed to the controllers against the truth", &RunRow::fed_error_rms);
  realism("fed_error_max", "m", "fed-pose error max",
          "largest position error of the pose fed to the controllers against the truth", &RunRow::fed_error_max);
  realism("odometry_error_max", "m", "odometry error max", "largest position error of the encoders' dead reckoning",
          &RunRow::odometry_error_max);
  m = realism("fixes_applied", "fixes", "fixes applied", "position fixes fused into the estimate",
              &RunRow::fixes_applied);
  m->format = MetricFormat::count;
  m->better = Better::none;
  m = realism("fixes_refused", "fixes", "fixes refused", "position fixes refused (gated, too old, invalid, ...)",
              &RunRow::fixes_refused);
  m->format = MetricFormat::count;
  m->better = Better::none;
  realism("high_slip_share", "1", "high-slip share",
          "share of the run either wheel's |slip ratio| was above twice the friction peak's (0 without traction)",
          &RunRow::high_slip_share);
  realism("unsown_distance", "m", "row left unsown",
          "row length the tool missed while the hitch control had it raised on slip (0 without hitch control)",
          &RunRow::unsown_distance);
  realism("seeds_unsown", "seeds", "seeds lost",
          "seeds that would have fallen on the unsown row (its length / spacing)", &RunRow::seeds_unsown);
  return out;
}

/// A JSON string literal of s (UTF-8 passed through; quotes, backslashes and control characters escaped).
std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

const char* formatName(MetricFormat f) {
  switch (f) {
    case MetricFormat::number: return "number";
    case MetricFormat::count: return "count";
    case MetricFormat::flag: return "flag";
  }
  return "";
}
const char* aggregationName(Aggregation a) {
  switch (a) {
    case Aggregation::median: return "median";
    case Aggregation::mean: return "mean";
    case Aggregation::share: return "share";
  }
  return "";
}
const char* betterName(Better b) {
  switch (b) {
    case Better::lower: return "lower";
    case Better::higher: return "higher";
    case Better::none: return "none";
  }
  return "";
}
}  // namespace

const std::vector<RunMetric>& runMetrics() {
  static const std::vector<RunMetric> metrics = buildMetrics();
  return metrics;
}

const std::vector<std::string>& runsCsvIdentityColumns() {
  static const std::vector<std::string> columns{
      "scenario", "set",        "controller", "seed",    "mass_scale",  "inertia_scale", "amplitude",
      "phase",    "noise_seed", "start_x",    "start_y", "start_theta", "failure",       "sensor_seed"};
  return columns;
}

std::string runMetricsJson() {
  std::string out = "[\n";
  const auto& metrics = runMetrics();
  for (std::size_t i = 0; i < metrics.size(); ++i) {
    const RunMetric& m = metrics[i];
    std::string plots;
    if (m.plots & kBoxPlot) plots += "\"box\"";
    if (m.plots & kSweepPlot) plots += std::string(plots.empty() ? "" : ", ") + "\"sweep\"";
    out += "  {\"name\": " + jsonString(m.name) + ", \"unit\": " + jsonString(m.unit) +
           ", \"label\": " + jsonString(m.label) + ", \"meaning\": " + jsonString(m.meaning) + ", \"format\": \"" +
           formatName(m.format) + "\", \"group\": \"" + (m.group == MetricGroup::realism ? "realism" : "always") +
           "\", \"aggregation\": \"" + aggregationName(m.aggregation) + "\", \"better\": \"" + betterName(m.better) +
           "\", \"compared\": " + (m.compared ? "true" : "false") + ", \"plots\": [" + plots +
           "], \"report_table\": " + (m.report_table ? "true" : "false") +
           ", \"overview_column\": " + std::to_string(m.overview_column) +
           ", \"overview_p95\": " + (m.overview_p95 ? "true" : "false") + "}" + (i + 1 < metrics.size() ? "," : "") +
           "\n";
  }
  return out + "]\n";
}

}  // namespace core
}  // namespace sowing_robot
