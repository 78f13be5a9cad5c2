// Seed maps: a run's seeds (core::Seed, the seed drill's record) as a CSV table and as GeoJSON (RFC 7946) a GIS
// opens as it is. The odom frame is taken as REP 103 has it, x east and y north, with its origin at a given
// WGS84 position; GeographicLib's LocalCartesian turns odom metres into longitude and latitude. Every file is
// written whole or not at all (a temporary file beside it, renamed). Errors come back as one line of text ("" for
// none); the seed_map command (src/tools/seed_map.cpp) prints them.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sowing_robot/core/planning/seeding.h"

namespace sowing_robot {
namespace seed_map {

/// The WGS84 position of the odom frame's origin.
struct GeoOrigin {
  double latitude = 0.0;   ///< [deg], -90..90
  double longitude = 0.0;  ///< [deg], -180..180
  double altitude = 0.0;   ///< height above the ellipsoid [m]
};

/// "LAT,LON" or "LAT,LON,ALT" (degrees, degrees, metres) into `origin`; "" or why not.
std::string parseOrigin(const std::string& text, GeoOrigin& origin);

/// The CSV header line's columns, in order.
extern const char* const kCsvHeader;  // "t,x,y,believed_x,believed_y,row,depth,detour"

/// One line per seed after the header (numbers as the shortest text that reads back to the same double; detour
/// 0 or 1).
std::string csvText(const std::vector<core::Seed>& seeds);
/// A CSV written by csvText read back; "" or why not (the file and line).
std::string readCsv(const std::string& path, std::vector<core::Seed>& seeds);

/// A FeatureCollection of Point features, one per seed, at [longitude, latitude] of where it fell; properties
/// t, row, depth, detour, x, y, believed_x, believed_y (odom [m]), believed_lon, believed_lat [deg] and
/// believed_offset (how far the robot's belief was from where the seed fell [m]).
std::string geoJsonText(const std::vector<core::Seed>& seeds, const GeoOrigin& origin);

/// `text` into `path` whole or not at all; "" or "cannot write PATH: reason".
std::string writeFileAtomically(const std::string& path, const std::string& text);
std::string writeCsv(const std::string& path, const std::vector<core::Seed>& seeds);
/// Without an origin nothing is written: GeoJSON is in WGS84 and the odom frame's position on Earth is not
/// known from the run.
std::string writeGeoJson(const std::string& path, const std::vector<core::Seed>& seeds,
                         const std::optional<GeoOrigin>& origin);

/// The seed_map command's arguments.
struct Options {
  std::string bag;
  std::string topic;    ///< "" : the bag's one topic of type sowing_robot/Seed
  std::string csv;      ///< "" : no CSV
  std::string geojson;  ///< "" : no GeoJSON (then origin is needed)
  std::optional<GeoOrigin> origin;
};
extern const char* const kUsage;
/// args: the command's arguments after its name. "" or the one line why not (a usage error: exit 2).
std::string parseArguments(const std::vector<std::string>& args, Options& options);
/// The files the options name, from `seeds`; "" or the first failure (a file written before it stays).
std::string writeMaps(const Options& options, const std::vector<core::Seed>& seeds);

}  // namespace seed_map
}  // namespace sowing_robot
