// field_info: reads a field file (a field's boundary and voids: GeoJSON in WGS84, or the local frame) and prints
// the field's area, each void's and the bounding box in the local frame, or the one line why the file is refused.
// The work is the field_file library's (include/sowing_robot/field_file/field_file.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sowing_robot/cli/options.h"
#include "sowing_robot/cli/usage.h"
#include "sowing_robot/core/common/polygon.h"
#include "sowing_robot/field_file/field_file.h"

namespace {
const char* const kUsage =
    "usage: rosrun sowing_robot field_info FILE [--origin LAT,LON[,ALT]]\n\n"
    "Reads a field file and prints the field's area, its voids' areas and its bounding box in the field's local\n"
    "frame (x east, y north, metres). FILE: GeoJSON in WGS84 (the boundary: the feature with \"role\": \"boundary\";\n"
    "voids: \"role\": \"void\", a Point with a \"radius\" for a circle; the boundary's holes) or a local-frame "
    "YAML/JSON\n"
    "(frame: local). Format, origin rule and errors: docs/field_file.md.\n\n"
    "Options:\n"
    "  --origin LAT,LON[,ALT]  the local frame's WGS84 origin (degrees, metres); takes the place of the file's\n"
    "                          \"origin\". A GeoJSON file without either is refused.\n"
    "  -h, --help              this text\n\n"
    "Exit: 0 read and checked; 2 a usage error or a file that is refused (one line on stderr).\n";
}  // namespace

int main(int argc, char** argv) {
  namespace ff = sowing_robot::field_file;
  namespace cli = sowing_robot::cli;
  cli::exitOnHelp(argc, argv, kUsage);
  std::vector<std::string> files;
  std::string origin_text;
  cli::po::options_description options;
  options.add_options()("origin", cli::po::value(&origin_text))("file", cli::po::value(&files));
  cli::Parse parse{"field_info", options, {}, [](const std::string&) { return "--origin needs LAT,LON[,ALT]"; }};
  parse.positional.add("file", -1);
  cli::po::variables_map vm;
  std::string error = cli::parseOptions(argc, argv, parse, vm);
  std::optional<ff::GeoOrigin> origin;
  if (error.empty() && vm.count("origin")) {
    ff::GeoOrigin o;
    error = sowing_robot::seed_map::parseOrigin(origin_text, o);
    origin = o;
  }
  if (error.empty() && files.size() > 1) error = "one file at a time (got " + files[0] + " and " + files[1] + ")";
  if (error.empty() && files.empty()) error = "no field file given (see field_info --help)";
  if (!error.empty()) {
    std::fprintf(stderr, "field_info: %s\n", error.c_str());
    return cli::kUsageExit;
  }
  const std::string& path = files.front();
  ff::FieldFile f;
  try {
    f = ff::readFieldFile(path, origin);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "field_info: %s\n", e.what());
    return cli::kUsageExit;
  }
  const sowing_robot::core::FieldBoundary& b = f.boundary;
  std::printf("field_info: %s (%s", path.c_str(), f.format.c_str());
  if (f.origin)
    std::printf(", origin lat %.7f lon %.7f alt %.1f m from %s", f.origin->latitude, f.origin->longitude,
                f.origin->altitude, f.origin_source.c_str());
  std::printf(")\n");
  const double outer = sowing_robot::core::ringArea(b.outer);
  Eigen::Vector2d lo = b.outer[0], hi = b.outer[0];
  for (const Eigen::Vector2d& v : b.outer) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  std::printf("boundary: %zu vertices, area %.1f m^2 (%.4f ha)\n", b.outer.size(), outer, outer / 1e4);
  std::printf("bounding box: x %.2f .. %.2f m, y %.2f .. %.2f m (%.2f m x %.2f m)\n", lo.x(), hi.x(), lo.y(), hi.y(),
              hi.x() - lo.x(), hi.y() - lo.y());
  double voids = 0.0;
  for (std::size_t i = 0; i < b.voids.size(); ++i) {
    const double a = sowing_robot::core::ringArea(b.voids[i]);
    voids += a;
    std::printf("void %s: %zu vertices, area %.1f m^2\n", f.void_names[i].c_str(), b.voids[i].size(), a);
  }
  for (std::size_t i = 0; i < b.circles.size(); ++i) {
    const double a = M_PI * b.circles[i].radius * b.circles[i].radius;
    voids += a;
    std::printf("void %s: circle at (%.2f, %.2f) m, radius %.2f m, area %.1f m^2\n", f.circle_names[i].c_str(),
                b.circles[i].x, b.circles[i].y, b.circles[i].radius, a);
  }
  // Voids may overlap each other; the sum then counts the shared part twice (a planner takes their union).
  std::printf("to sow: %.1f m^2 (%.4f ha) = boundary - voids (%.1f m^2)\n", outer - voids, (outer - voids) / 1e4,
              voids);
  return 0;
}
