#include "sowing_robot/seed_map/seed_map.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <GeographicLib/LocalCartesian.hpp>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sowing_robot/cli/options.h"

namespace sowing_robot {
namespace seed_map {

const char* const kCsvHeader = "t,x,y,believed_x,believed_y,row,depth,detour";

const char* const kUsage =
    "usage: rosrun sowing_robot seed_map BAG [--csv FILE] [--geojson FILE --origin LAT,LON[,ALT]] [--topic NAME]\n"
    "       rosrun sowing_robot seed_map --help\n\n"
    "Writes the seeds a run recorded (the seed drill's sowing_robot/Seed messages, `seeds/record` in a bag of\n"
    "sim.launch record:=lean or full) as a seed map:\n"
    "  --csv FILE       one line per seed: t,x,y,believed_x,believed_y,row,depth,detour (odom frame [m], s)\n"
    "  --geojson FILE   an RFC 7946 FeatureCollection of Point features in WGS84 longitude/latitude\n"
    "  --origin LAT,LON[,ALT]  the WGS84 position [deg, deg, m] of the odom frame's origin (x east, y north);\n"
    "                   needed by --geojson\n"
    "  --topic NAME     the seed topic when the bag holds several (default: its one topic of that type)\n"
    "Each file is written whole or not at all. Exit 0; 1 the bag cannot be read, holds no seed, or a file\n"
    "cannot be written; 2 a usage error. docs/seed_map.md.\n"
    "\nOptions:\n  -h, --help   this text\n";

namespace {

bool parseDouble(const std::string& text, double& value) {
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, value);
  return r.ec == std::errc() && r.ptr == end && !text.empty();
}

bool parseInt(const std::string& text, int& value) {
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, value);
  return r.ec == std::errc() && r.ptr == end && !text.empty();
}

/// The shortest text that reads back to the same double.
void appendNumber(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, sep)) parts.push_back(part);
  if (!text.empty() && text.back() == sep) parts.emplace_back();
  return parts;
}

/// A number for JSON: NaN and infinities have no JSON form (RFC 8259), so they become null.
nlohmann::ordered_json number(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json();
}

}  // namespace

std::string parseOrigin(const std::string& text, GeoOrigin& origin) {
  const std::vector<std::string> parts = split(text, ',');
  GeoOrigin o;
  if ((parts.size() != 2 && parts.size() != 3) || !parseDouble(parts[0], o.latitude) ||
      !parseDouble(parts[1], o.longitude) || (parts.size() == 3 && !parseDouble(parts[2], o.altitude)))
    return "origin '" + text + "' is not LAT,LON or LAT,LON,ALT (degrees, degrees, metres; e.g. 48.2,16.37,180)";
  if (!(std::fabs(o.latitude) <= 90.0) || !(std::fabs(o.longitude) <= 180.0) || !std::isfinite(o.altitude))
    return "origin '" + text + "' is off the Earth: latitude within [-90, 90], longitude within [-180, 180]";
  origin = o;
  return "";
}

std::string csvText(const std::vector<core::Seed>& seeds) {
  std::string out = kCsvHeader;
  out += '\n';
  for (const core::Seed& s : seeds) {
    for (double v : {s.t, s.truth.x(), s.truth.y(), s.believed.x(), s.believed.y()}) {
      appendNumber(out, v);
      out += ',';
    }
    out += std::to_string(s.row);
    out += ',';
    appendNumber(out, s.depth);
    out += s.detour ? ",1\n" : ",0\n";
  }
  return out;
}

std::string readCsv(const std::string& path, std::vector<core::Seed>& seeds) {
  std::ifstream in(path);
  if (!in) return "cannot read " + path + ": " + std::strerror(errno);
  std::string line;
  if (!std::getline(in, line) || line != kCsvHeader)
    return path + ": line 1 is not the header " + std::string(kCsvHeader);
  std::vector<core::Seed> out;
  for (int n = 2; std::getline(in, line); ++n) {
    const std::vector<std::string> f = split(line, ',');
    core::Seed s;
    double v[5];
    bool ok = f.size() == 8 && (f[7] == "0" || f[7] == "1") && parseInt(f[5], s.row) && parseDouble(f[6], s.depth);
    for (int i = 0; ok && i < 5; ++i) ok = parseDouble(f[i], v[i]);
    if (!ok) return path + ": line " + std::to_string(n) + " is not " + kCsvHeader + ": " + line;
    s.t = v[0];
    s.truth = {v[1], v[2]};
    s.believed = {v[3], v[4]};
    s.detour = f[7] == "1";
    out.push_back(s);
  }
  seeds = std::move(out);
  return "";
}

std::string geoJsonText(const std::vector<core::Seed>& seeds, const GeoOrigin& origin) {
  const GeographicLib::LocalCartesian local(origin.latitude, origin.longitude, origin.altitude);
  // One feature a line: a large map stays readable and its diffs small.
  std::string out = "{\"type\": \"FeatureCollection\", \"features\": [\n";
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    const core::Seed& s = seeds[i];
    double lat, lon, h, blat, blon, bh;
    local.Reverse(s.truth.x(), s.truth.y(), 0.0, lat, lon, h);
    local.Reverse(s.believed.x(), s.believed.y(), 0.0, blat, blon, bh);
    // In the order of RFC 7946's examples and as listed in seed_map.h, not sorted by key.
    const nlohmann::ordered_json feature = {
        {"type", "Feature"},
        {"geometry", {{"type", "Point"}, {"coordinates", {number(lon), number(lat)}}}},
        {"properties",
         {{"t", number(s.t)},
          {"row", s.row},
          {"depth", number(s.depth)},
          {"detour", s.detour},
          {"x", number(s.truth.x())},
          {"y", number(s.truth.y())},
          {"believed_x", number(s.believed.x())},
          {"believed_y", number(s.believed.y())},
          {"believed_lon", number(blon)},
          {"believed_lat", number(blat)},
          {"believed_offset", number((s.believed - s.truth).norm())}}}};
    out += feature.dump();
    out += i + 1 < seeds.size() ? ",\n" : "\n";
  }
  out += "]}\n";
  return out;
}

std::string writeFileAtomically(const std::string& path, const std::string& text) {
  const auto failed = [&path](int err) { return "cannot write " + path + ": " + std::strerror(err); };
  std::string tmp = path + ".XXXXXX";
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0) return failed(errno);
  ::fchmod(fd, 0644);  // mkstemp's 0600 would hide the map from everyone else
  int err = 0;
  for (std::size_t done = 0; done < text.size() && err == 0;) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno != EINTR) err = errno;
    if (n > 0) done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err == 0 && std::rename(tmp.c_str(), path.c_str()) != 0) err = errno;
  if (err != 0) {
    ::unlink(tmp.c_str());
    return failed(err);
  }
  return "";
}

std::string writeCsv(const std::string& path, const std::vector<core::Seed>& seeds) {
  return writeFileAtomically(path, csvText(seeds));
}

std::string writeGeoJson(const std::string& path, const std::vector<core::Seed>& seeds,
                         const std::optional<GeoOrigin>& origin) {
  if (!origin)
    return "GeoJSON " + path +
           " needs --origin LAT,LON[,ALT]: the WGS84 position of the odom frame's origin (GeoJSON is in longitude "
           "and latitude)";
  return writeFileAtomically(path, geoJsonText(seeds, *origin));
}

std::string parseArguments(const std::vector<std::string>& args, Options& options) {
  namespace po = cli::po;
  Options o;
  std::string origin_text;
  std::vector<std::string> bags;
  po::options_description declared;
  declared.add_options()("csv", po::value(&o.csv))("geojson", po::value(&o.geojson))("origin", po::value(&origin_text))(
      "topic", po::value(&o.topic))("bag", po::value(&bags));
  cli::Parse parse{"seed_map", declared};
  parse.positional.add("bag", -1);
  std::vector<const char*> argv{"seed_map"};
  for (const std::string& a : args) argv.push_back(a.c_str());
  po::variables_map vm;
  const std::string error = cli::parseOptions(static_cast<int>(argv.size()), argv.data(), parse, vm);
  if (!error.empty()) return error;
  for (const char* key : {"csv", "geojson", "origin", "topic"})
    if (vm.count(key) && vm[key].as<std::string>().empty())
      return "--" + std::string(key) + " needs a value (see seed_map --help)";
  if (vm.count("origin")) {
    GeoOrigin origin;
    const std::string e = parseOrigin(origin_text, origin);
    if (!e.empty()) return e;
    o.origin = origin;
  }
  if (bags.size() > 1) return "one bag at a time (got " + bags[0] + " and " + bags[1] + ")";
  if (!bags.empty()) o.bag = bags[0];
  if (o.bag.empty()) return "no bag given (see seed_map --help)";
  if (o.csv.empty() && o.geojson.empty()) return "nothing to write: give --csv FILE and/or --geojson FILE";
  if (!o.geojson.empty() && !o.origin)
    return "--geojson needs --origin LAT,LON[,ALT]: the WGS84 position of the odom frame's origin";
  options = o;
  return "";
}

std::string writeMaps(const Options& options, const std::vector<core::Seed>& seeds) {
  if (!options.csv.empty()) {
    const std::string error = writeCsv(options.csv, seeds);
    if (!error.empty()) return error;
  }
  if (!options.geojson.empty()) return writeGeoJson(options.geojson, seeds, options.origin);
  return "";
}

}  // namespace seed_map
}  // namespace sowing_robot
