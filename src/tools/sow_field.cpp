// sow_field: a field file planned (coverage_planner.h) and sown in-process (core/evaluation/coverage_run.h) under a
// profile with a controller pair and its gains; prints the plan's coverage figures and the seed record's figures, and
// writes the seed map (the seed_map library's CSV or GeoJSON). docs/coverage.md, "Sowing a planned field".
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>

#include "sowing_robot/cli/options.h"
#include "sowing_robot/cli/usage.h"
#include "sowing_robot/core/evaluation/coverage_run.h"
#include "sowing_robot/core/planning/coverage_metrics.h"
#include "sowing_robot/field_file/field_file.h"
#include "sowing_robot/scenario_file/scenario_loader.h"
#include "sowing_robot/seed_map/seed_map.h"

namespace {

namespace core = sowing_robot::core;
namespace ff = sowing_robot::field_file;
namespace sf = sowing_robot::scenario_file;
namespace sm = sowing_robot::seed_map;

const char* const kUsage =
    "usage: rosrun sowing_robot sow_field --field FILE [--profile NAME|FILE|none] [--outer NAME --inner NAME]\n"
    "                                     [--start X,Y,YAW] [--origin LAT,LON[,ALT]] [--seed-map "
    "OUT.csv|OUT.geojson]\n\n"
    "Plans a coverage route over a field file (boundary and voids, docs/field_file.md; the planner's defaults: one\n"
    "row per pass, 1 m apart, two headland passes, heading auto, each swath driven on by the tool's 0.45 m) and sows "
    "it\n"
    "in-process: the closed loop under the profile with the controller pair and the gains tuned for it, the path\n"
    "follower on the route from the start pose, the seed drill on the plan's rows. Prints the plan's coverage figures\n"
    "and the seed record's (planned row length, sown share, area sown, quality of feed, lateral p95, time, work).\n\n"
    "Options:\n"
    "  --field FILE            the field file (GeoJSON in WGS84, or a local-frame YAML/JSON)\n"
    "  --profile NAME|FILE     the set-up (default field: config/profiles/field.yaml, gains config/tuned/field/);\n"
    "                          none: the no-slip plant fed the truth, the pair's table gains\n"
    "  --outer NAME            outer controller (default rpp); --inner NAME inner controller (default pid)\n"
    "  --start X,Y,YAW         the robot's start pose in the field's frame [m, m, rad] (default: 1 m before the\n"
    "                          first swath's start, facing along it)\n"
    "  --origin LAT,LON[,ALT]  the local frame's WGS84 origin in place of the file's (GeoJSON fields, seed maps)\n"
    "  --seed-map OUT          the seed record as CSV (OUT.csv) or GeoJSON (OUT.geojson: needs the field's origin)\n"
    "  -h, --help              this text\n\n"
    "Exit: 0 sown (whatever the figures); 1 the run failed (an invalid set-up, a file not written); 2 a usage error\n"
    "or a field file that is refused.\n";

struct Options {
  std::string field, profile = "field", outer = "rpp", inner = "pid", seed_map;
  std::optional<core::Pose2D> start;
  std::optional<ff::GeoOrigin> origin;
};

/// "X,Y,YAW" into pose; "" or why not.
std::string parsePose(const std::string& text, core::Pose2D& pose) {
  double v[3];
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3)
    return "--start needs X,Y,YAW (metres, metres, radians), got '" + text + "'";
  pose = {v[0], v[1], v[2]};
  return "";
}

/// The command's arguments into `o`; "" or the one line why not.
std::string parseArguments(int argc, char** argv, Options& o) {
  namespace cli = sowing_robot::cli;
  std::string start, origin;
  cli::po::options_description options;
  options.add_options()("field", cli::po::value(&o.field))("profile", cli::po::value(&o.profile))(
      "outer", cli::po::value(&o.outer))("inner", cli::po::value(&o.inner))("start", cli::po::value(&start))(
      "origin", cli::po::value(&origin))("seed-map", cli::po::value(&o.seed_map));
  cli::po::variables_map vm;
  const std::string error = cli::parseOptions(argc, argv, {"sow_field", options}, vm);
  if (!error.empty()) return error;
  if (vm.count("start")) {
    core::Pose2D p;
    const std::string e = parsePose(start, p);
    if (!e.empty()) return e;
    o.start = p;
  }
  if (vm.count("origin")) {
    ff::GeoOrigin g;
    const std::string e = sm::parseOrigin(origin, g);
    if (!e.empty()) return e;
    o.origin = g;
  }
  if (o.field.empty()) return "no field file given (--field FILE; see sow_field --help)";
  const bool csv = o.seed_map.size() > 4 && o.seed_map.compare(o.seed_map.size() - 4, 4, ".csv") == 0;
  const bool geo = o.seed_map.size() > 8 && o.seed_map.compare(o.seed_map.size() - 8, 8, ".geojson") == 0;
  if (!o.seed_map.empty() && !csv && !geo)
    return "--seed-map " + o.seed_map + ": the name must end in .csv or .geojson";
  return "";
}

/// The run's set-up: the pair, the profile's plant and layers, the gains tuned for the pair under it, the tool's
/// run-out. Throws std::invalid_argument.
core::CoverageRunSetup setupOf(const Options& o) {
  core::CoverageRunSetup s;
  std::string e = core::parseControllerPair(o.outer + "+" + o.inner, s.scenario.outer, s.scenario.inner,
                                            s.scenario.sliding.adaptive);
  if (!e.empty()) throw std::invalid_argument(e);
  if (o.profile != "none") {
    const sf::ProfileFiles files = sf::resolveProfile(o.profile, SOWING_SOURCE_DIR);
    sf::applyProfileTo(files.file, s.loop);
    const std::string gains = files.gains_dir.empty() ? "" : sf::tunedGainsFile(files.gains_dir, s.scenario);
    if (!gains.empty()) sf::applyTunedGains(gains, s.scenario);
    std::printf("sow_field: profile %s, %s gains %s\n", files.file.c_str(), s.scenario.controllerName().c_str(),
                gains.empty() ? "from the parameter tables (none tuned for the profile)" : gains.c_str());
  } else {
    std::printf("sow_field: no profile, %s gains from the parameter tables\n", s.scenario.controllerName().c_str());
  }
  s.coverage.run_out = std::max(0.0, -s.loop.tool.x());  // the tool point trails the axle (URDF tool_link)
  return s;
}

void printPlan(const core::CoveragePlan& plan, const core::CoverageFigures& f, double ms) {
  std::printf(
      "plan (%.0f ms): field %.0f m^2, workable %.0f m^2; heading %.3f rad, %d swaths in %d parts, %zu headland "
      "loops with %zu headland rows; path %.0f m (turns %.0f m)\n",
      ms, f.field_area, f.workable_area, plan.heading, f.swaths, plan.parts, plan.headland_rings.size(),
      plan.headland_rows.size(), f.path_length, f.turn_length);
  std::printf(
      "coverage: %.2f %% of the inner field by the swaths, %.2f %% of the workable field in all (%.0f m^2, the rows' "
      "strips %.0f m^2); overlap %.2f %%, missed %.2f %%, outside %.2f %%\n",
      100.0 * f.covered_inner_share, 100.0 * f.covered_share, f.covered_area, f.row_area, 100.0 * f.overlap_share,
      100.0 * f.missed_share, 100.0 * f.outside_share);
}

/// The seed map of `o` from the run's record; "" or why not.
std::string writeSeedMap(const Options& o, const core::CoverageRunReport& r, const std::optional<ff::GeoOrigin>& g) {
  if (o.seed_map.empty()) return "";
  const bool csv = o.seed_map.compare(o.seed_map.size() - 4, 4, ".csv") == 0;
  const std::string e = csv ? sm::writeCsv(o.seed_map, r.seed_record) : sm::writeGeoJson(o.seed_map, r.seed_record, g);
  if (e.empty()) std::printf("seed map: %zu seeds into %s\n", r.seed_record.size(), o.seed_map.c_str());
  return e;
}

/// Plans, sows and prints; the exit status.
int sow(const Options& o, const ff::FieldFile& file) {
  using Clock = std::chrono::steady_clock;
  try {
    core::CoverageRunSetup setup = setupOf(o);
    const auto t0 = Clock::now();
    const core::CoveragePlan plan = core::planCoverage(file.boundary, setup.coverage);
    const double plan_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    const core::CoverageFigures figures = core::coverageFigures(file.boundary, plan);
    printPlan(plan, figures, plan_ms);
    const core::Swath& first = plan.swaths.front();
    const Eigen::Vector2d along = (first.b - first.a).normalized();
    const Eigen::Vector2d behind = first.a - along;
    setup.start = o.start ? *o.start : core::Pose2D{behind.x(), behind.y(), std::atan2(along.y(), along.x())};
    setup.keep_seeds = !o.seed_map.empty();
    const auto t1 = Clock::now();
    const core::CoverageRunReport r = core::runCoverage(plan, setup);
    const double wall = std::chrono::duration<double>(Clock::now() - t1).count();
    std::printf("sown from (%.2f, %.2f, %.3f) in %.1f s wall:\n%s\n", setup.start.x, setup.start.y, setup.start.theta,
                wall, r.summary().c_str());
    std::printf("area sown %.0f m^2 = %.2f %% of the plan's covered %.0f m^2 (%.2f %% of its rows' %.0f m^2)\n",
                r.area_sown, 100.0 * r.area_sown / figures.covered_area, figures.covered_area,
                100.0 * r.area_sown / figures.row_area, figures.row_area);
    const std::string e = writeSeedMap(o, r, file.origin);
    if (!e.empty()) {
      std::fprintf(stderr, "sow_field: %s\n", e.c_str());
      return 1;
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "sow_field: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  namespace cli = sowing_robot::cli;
  cli::exitOnHelp(argc, argv, kUsage);
  Options o;
  const std::string e = parseArguments(argc, argv, o);
  if (!e.empty()) {
    std::fprintf(stderr, "sow_field: %s\n", e.c_str());
    return cli::kUsageExit;
  }
  ff::FieldFile file;
  try {
    file = ff::readFieldFile(o.field, o.origin);
  } catch (const std::invalid_argument& ex) {
    std::fprintf(stderr, "sow_field: %s\n", ex.what());
    return cli::kUsageExit;
  }
  return sow(o, file);
}
