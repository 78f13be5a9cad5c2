// Field files: a field's outer boundary and its voids (areas not to be sown: polygons and circles) read into
// core::FieldBoundary in the field's local ENU frame (x east, y north, metres). Two formats (docs/field_file.md):
//   * GeoJSON (RFC 7946, WGS84 longitude/latitude) as farm software or a GNSS walk gives it: a FeatureCollection,
//     a Feature, or a bare Polygon/MultiPolygon. The boundary is the feature with property "role": "boundary" (else
//     the first Polygon); features with "role": "void" are voids (a Polygon, a MultiPolygon, or a Point with a
//     "radius" [m] for a circle), and the boundary's holes are voids too. GeographicLib's LocalCartesian turns
//     longitude/latitude into ENU metres about the origin: the caller's, else the file's top-level
//     "origin": {"lat": .., "lon": .., "alt": ..}; without either a WGS84 file is refused.
//   * A local-frame file (YAML or JSON, `frame: local`): boundary: [[x, y], ...], voids: [[[x, y], ...], ...],
//     circles: [{x, y, radius}, ...], already in metres.
// The field is then checked: each ring a simple polygon of >= 3 finite vertices (Boost.Geometry's is_valid, via
// core/common/polygon.h), each void and circle inside the boundary, each circle's radius > 0.
// Errors: std::invalid_argument with one line "PATH: what is wrong", naming the feature or key.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sowing_robot/core/planning/field_boundary.h"
#include "sowing_robot/seed_map/seed_map.h"

namespace sowing_robot {
namespace field_file {

/// The WGS84 origin of the local frame (the seed maps' type: latitude, longitude [deg], altitude [m]).
using GeoOrigin = seed_map::GeoOrigin;

/// A field file as read: the field, and where its names and origin came from (for a report such as field_info's).
struct FieldFile {
  core::FieldBoundary boundary;
  std::string format;                     ///< "GeoJSON (WGS84)" or "local frame"
  std::optional<GeoOrigin> origin;        ///< the origin used (GeoJSON only)
  std::string origin_source;              ///< "the file" or "the caller" (GeoJSON only)
  std::vector<std::string> void_names;    ///< per boundary.voids entry: its feature or key ("features[2] 'pond'")
  std::vector<std::string> circle_names;  ///< per boundary.circles entry
};

/// Reads and checks `path`. `origin`, when given, is the local frame's origin for a GeoJSON file and takes the
/// place of the file's own "origin" (a launch or command-line argument is the more deliberate choice); a
/// local-frame file ignores it. Throws std::invalid_argument("PATH: what is wrong").
FieldFile readFieldFile(const std::string& path, const std::optional<GeoOrigin>& origin = std::nullopt);

/// readFieldFile(path, origin).boundary.
core::FieldBoundary loadFieldBoundary(const std::string& path, const std::optional<GeoOrigin>& origin = std::nullopt);

/// "" when `field` is a field a planner can take (the checks above, in its local frame), else one line naming the
/// ring ("the field boundary", "void 1", "circle 0" or the names given, as readFieldFile names them).
std::string checkFieldBoundary(const core::FieldBoundary& field, const std::vector<std::string>& void_names = {},
                               const std::vector<std::string>& circle_names = {});

}  // namespace field_file
}  // namespace sowing_robot
