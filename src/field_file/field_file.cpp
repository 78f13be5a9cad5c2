#include "sowing_robot/field_file/field_file.h"

#include <yaml-cpp/yaml.h>
#include <GeographicLib/LocalCartesian.hpp>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "sowing_robot/core/common/polygon.h"
#include "sowing_robot/core/common/validation.h"

namespace sowing_robot {
namespace field_file {
namespace {

using core::Ring;
using nlohmann::json;

/// What went wrong in the file; readFieldFile puts the path in front.
struct FileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
[[noreturn]] void fail(const std::string& what) { throw FileError(what); }

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(std::string("cannot read the file: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) fail(std::string("cannot read the file: ") + std::strerror(errno));
  return text.str();
}

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// A YAML document as JSON (maps, lists, numbers where a scalar reads as one, else strings): the local format is
/// then read by one parser whichever syntax it came in.
json yamlToJson(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      json out = json::object();
      for (const auto& kv : node) out[kv.first.as<std::string>()] = yamlToJson(kv.second);
      return out;
    }
    case YAML::NodeType::Sequence: {
      json out = json::array();
      for (const auto& item : node) out.push_back(yamlToJson(item));
      return out;
    }
    case YAML::NodeType::Scalar: {
      double v = 0.0;
      if (YAML::convert<double>::decode(node, v)) return v;
      return node.Scalar();
    }
    default: return nullptr;
  }
}

json parseFile(const std::string& path, const std::string& text) {
  if (endsWith(path, ".yaml") || endsWith(path, ".yml")) {
    try {
      return yamlToJson(YAML::Load(text));
    } catch (const YAML::Exception& e) {
      fail("not YAML (line " + std::to_string(e.mark.line + 1) + ": " + e.msg + ")");
    }
  }
  try {
    return json::parse(text);
  } catch (const json::exception& e) {  // a syntax error, or a number beyond double's range (1e999)
    std::string what = e.what();
    const std::size_t at = what.find("] ");  // "[json.exception.parse_error.101] parse error at line 1, ..."
    fail("not JSON (" + (at == std::string::npos ? what : what.substr(at + 2)) + ")");
  }
}

const json* member(const json& object, const char* key) {
  if (!object.is_object()) return nullptr;
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

double number(const json& v, const std::string& name) {
  if (!v.is_number()) fail(name + " must be a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) fail(name + " = " + core::formatNumber(d) + " must be finite");
  return d;
}

// --- GeoJSON ------------------------------------------------------------------------------------------------------

/// The WGS84 -> local ENU conversion, at the origin's height (a field is flat in its frame; heights are ignored).
class Projection {
 public:
  explicit Projection(const GeoOrigin& o) : local_(o.latitude, o.longitude, o.altitude), height_(o.altitude) {}
  Eigen::Vector2d toLocal(double lon, double lat) const {
    double x = 0.0, y = 0.0, z = 0.0;
    local_.Forward(lat, lon, height_, x, y, z);
    return {x, y};
  }

 private:
  GeographicLib::LocalCartesian local_;
  double height_;
};

/// A GeoJSON linear ring ([[lon, lat], ...], closed by repeating the first position) in the local frame, without
/// the closing position.
Ring readGeoRing(const json& positions, const Projection& projection, const std::string& name) {
  if (!positions.is_array()) fail(name + " must be a list of [longitude, latitude] positions");
  Ring ring;
  std::vector<std::pair<double, double>> lonlat;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const std::string p = name + "[" + std::to_string(i) + "]";
    const json& pos = positions[i];
    if (!pos.is_array() || pos.size() < 2) fail(p + " must be a position [longitude, latitude]");
    const double lon = number(pos[0], p + " longitude"), lat = number(pos[1], p + " latitude");
    if (!(std::fabs(lat) <= 90.0)) fail(p + " latitude " + core::formatNumber(lat) + " is outside [-90, 90]");
    if (!(std::fabs(lon) <= 180.0)) fail(p + " longitude " + core::formatNumber(lon) + " is outside [-180, 180]");
    lonlat.emplace_back(lon, lat);
  }
  if (lonlat.size() > 1 && lonlat.front() == lonlat.back()) lonlat.pop_back();  // RFC 7946 closes rings
  if (lonlat.size() < 3)
    fail(name + " has " + std::to_string(lonlat.size()) + " distinct vertices; a polygon needs at least 3");
  for (const auto& [lon, lat] : lonlat) ring.push_back(projection.toLocal(lon, lat));
  return ring;
}

/// A Polygon's coordinates: the outer ring, then its holes.
std::vector<Ring> readGeoPolygon(const json& coordinates, const Projection& projection, const std::string& name) {
  if (!coordinates.is_array() || coordinates.empty())
    fail(name + " coordinates must be a list of rings (the outer ring first)");
  std::vector<Ring> rings;
  for (std::size_t r = 0; r < coordinates.size(); ++r)
    rings.push_back(
        readGeoRing(coordinates[r], projection, name + (r == 0 ? " outer ring" : " hole " + std::to_string(r))));
  return rings;
}

struct Feature {
  std::string name;  // "features[2] 'pond'"
  std::string role;  // "boundary", "void" or ""
  const json* geometry = nullptr;
  const json* properties = nullptr;
  std::string type;  // the geometry's type
};

std::vector<Feature> features(const json& root) {
  const json* type = member(root, "type");
  if (!type || !type->is_string())
    fail("neither GeoJSON (no \"type\") nor a local-frame field file (no \"frame\": \"local\")");
  const std::string t = type->get<std::string>();
  std::vector<Feature> out;
  const auto add = [&out](const json& f, const std::string& name) {
    Feature feature;
    feature.name = name;
    if (const json* ft = member(f, "type"); ft && *ft == "Feature") {
      feature.geometry = member(f, "geometry");
      feature.properties = member(f, "properties");
    } else {
      feature.geometry = &f;  // a bare geometry
    }
    if (feature.properties && feature.properties->is_object()) {
      if (const json* n = member(*feature.properties, "name"); n && n->is_string())
        feature.name += " '" + n->get<std::string>() + "'";
      if (const json* r = member(*feature.properties, "role")) {
        if (!r->is_string() || (*r != "boundary" && *r != "void"))
          fail(feature.name + ": property \"role\" must be \"boundary\" or \"void\"");
        feature.role = r->get<std::string>();
      }
    }
    if (feature.geometry && feature.geometry->is_object())
      if (const json* gt = member(*feature.geometry, "type"); gt && gt->is_string())
        feature.type = gt->get<std::string>();
    out.push_back(feature);
  };
  if (t == "FeatureCollection") {
    const json* list = member(root, "features");
    if (!list || !list->is_array()) fail("a FeatureCollection needs a \"features\" list");
    for (std::size_t i = 0; i < list->size(); ++i) {
      if (!(*list)[i].is_object()) fail("features[" + std::to_string(i) + "] must be a Feature object");
      add((*list)[i], "features[" + std::to_string(i) + "]");
    }
  } else if (t == "Feature" || t == "Polygon" || t == "MultiPolygon") {
    add(root, t == "Feature" ? "feature" : t);
  } else {
    fail("GeoJSON type '" + t + "' holds no field: a FeatureCollection, Feature, Polygon or MultiPolygon is needed");
  }
  return out;
}

GeoOrigin fileOrigin(const json& o) {
  const json* lat = member(o, "lat");
  const json* lon = member(o, "lon");
  if (!lat || !lon) fail("\"origin\" must be {\"lat\": degrees, \"lon\": degrees[, \"alt\": metres]}");
  GeoOrigin g;
  g.latitude = number(*lat, "origin lat");
  g.longitude = number(*lon, "origin lon");
  if (const json* alt = member(o, "alt")) g.altitude = number(*alt, "origin alt");
  if (!(std::fabs(g.latitude) <= 90.0)) fail("origin lat " + core::formatNumber(g.latitude) + " is outside [-90, 90]");
  if (!(std::fabs(g.longitude) <= 180.0))
    fail("origin lon " + core::formatNumber(g.longitude) + " is outside [-180, 180]");
  return g;
}

void readGeoJson(const json& root, const std::optional<GeoOrigin>& caller, FieldFile& out) {
  std::vector<Feature> list = features(root);  // the GeoJSON's shape first: "not GeoJSON" before "no origin"
  out.format = "GeoJSON (WGS84)";
  if (caller) {
    out.origin = caller;
    out.origin_source = "the caller";
  } else if (const json* o = member(root, "origin")) {
    out.origin = fileOrigin(*o);
    out.origin_source = "the file";
  } else {
    fail(
        "WGS84 coordinates without an origin: give the file a top-level \"origin\": {\"lat\": .., \"lon\": ..} or "
        "the origin as an argument (--origin LAT,LON)");
  }
  const Projection projection(*out.origin);

  const Feature* boundary = nullptr;
  for (const Feature& f : list)
    if (f.role == "boundary") {
      if (boundary)
        fail(f.name + ": a second feature with \"role\": \"boundary\" (the first is " + boundary->name + ")");
      boundary = &f;
    }
  if (!boundary)
    for (const Feature& f : list)
      if (f.role.empty() && f.type == "Polygon") {
        boundary = &f;
        break;
      }
  if (!boundary && list.size() == 1 && list[0].type == "MultiPolygon" && list[0].role.empty()) boundary = &list[0];
  if (!boundary) fail("no field boundary: no feature has \"role\": \"boundary\" and none is a Polygon");

  const auto coordinates = [](const Feature& f) -> const json& {
    const json* c = f.geometry ? member(*f.geometry, "coordinates") : nullptr;
    if (!c) fail(f.name + ": its geometry has no \"coordinates\"");
    return *c;
  };
  // The boundary: one Polygon (a MultiPolygon of one polygon, as some tools write every area, is taken too).
  const json* polygon = nullptr;
  if (boundary->type == "Polygon") {
    polygon = &coordinates(*boundary);
  } else if (boundary->type == "MultiPolygon" && coordinates(*boundary).is_array() &&
             coordinates(*boundary).size() == 1) {
    polygon = &coordinates(*boundary)[0];
  } else {
    fail(boundary->name + ": the field boundary must be one Polygon (got " +
         (boundary->type.empty() ? std::string("no geometry") : boundary->type) + ")");
  }
  std::vector<Ring> rings = readGeoPolygon(*polygon, projection, boundary->name);
  out.boundary.outer = rings[0];
  for (std::size_t h = 1; h < rings.size(); ++h) {
    out.boundary.voids.push_back(rings[h]);
    out.void_names.push_back(boundary->name + " hole " + std::to_string(h));
  }

  for (const Feature& f : list) {
    if (&f == boundary || f.role != "void") continue;  // features of no role are not the field's (a track, a note)
    if (f.type == "Polygon" || f.type == "MultiPolygon") {
      const json& c = coordinates(f);
      const bool multi = f.type == "MultiPolygon";
      if (multi && !c.is_array()) fail(f.name + ": a MultiPolygon's coordinates must be a list of polygons");
      for (std::size_t k = 0; k < (multi ? c.size() : 1); ++k) {
        const std::string name = multi ? f.name + " polygon " + std::to_string(k) : f.name;
        std::vector<Ring> vr = readGeoPolygon(multi ? c[k] : c, projection, name);
        if (vr.size() > 1) fail(name + ": a void with holes (an island to sow inside a void) is not supported");
        out.boundary.voids.push_back(vr[0]);
        out.void_names.push_back(name);
      }
    } else if (f.type == "Point") {
      const json& c = coordinates(f);
      if (!c.is_array() || c.size() < 2) fail(f.name + ": a Point's coordinates must be [longitude, latitude]");
      const double lon = number(c[0], f.name + " longitude"), lat = number(c[1], f.name + " latitude");
      if (!(std::fabs(lat) <= 90.0)) fail(f.name + " latitude " + core::formatNumber(lat) + " is outside [-90, 90]");
      if (!(std::fabs(lon) <= 180.0))
        fail(f.name + " longitude " + core::formatNumber(lon) + " is outside [-180, 180]");
      const json* radius = f.properties ? member(*f.properties, "radius") : nullptr;
      if (!radius) fail(f.name + ": a Point void needs a \"radius\" property [m]");
      const Eigen::Vector2d centre = projection.toLocal(lon, lat);
      core::Obstacle circle;
      circle.x = centre.x();
      circle.y = centre.y();
      circle.radius = number(*radius, f.name + " radius");
      out.boundary.circles.push_back(circle);
      out.circle_names.push_back(f.name);
    } else {
      fail(f.name + ": a void must be a Polygon, a MultiPolygon or a Point with a radius (got " +
           (f.type.empty() ? std::string("no geometry") : f.type) + ")");
    }
  }
}

// --- Local frame ------------------------------------------------------------------------------------------------

Ring readLocalRing(const json& list, const std::string& name) {
  if (!list.is_array()) fail(name + " must be a list of [x, y] vertices [m]");
  Ring ring;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string v = name + "[" + std::to_string(i) + "]";
    if (!list[i].is_array() || list[i].size() != 2) fail(v + " must be a vertex [x, y] of two numbers");
    ring.emplace_back(number(list[i][0], v + " x"), number(list[i][1], v + " y"));
  }
  if (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();  // a closed ring as GeoJSON writes it
  if (ring.size() < 3)
    fail(name + " has " + std::to_string(ring.size()) + " distinct vertices; a polygon needs at least 3");
  return ring;
}

void readLocal(const json& root, FieldFile& out) {
  out.format = "local frame";
  for (const auto& kv : root.items())
    if (kv.key() != "frame" && kv.key() != "boundary" && kv.key() != "voids" && kv.key() != "circles")
      fail("unknown key '" + kv.key() + "' (a local-frame field has frame, boundary, voids, circles)");
  const json* boundary = member(root, "boundary");
  if (!boundary) fail("no field boundary: the key \"boundary\" ([[x, y], ...]) is missing");
  out.boundary.outer = readLocalRing(*boundary, "boundary");
  if (const json* voids = member(root, "voids")) {
    if (!voids->is_array()) fail("voids must be a list of polygons [[x, y], ...]");
    for (std::size_t i = 0; i < voids->size(); ++i) {
      const std::string name = "voids[" + std::to_string(i) + "]";
      out.boundary.voids.push_back(readLocalRing((*voids)[i], name));
      out.void_names.push_back(name);
    }
  }
  if (const json* circles = member(root, "circles")) {
    if (!circles->is_array()) fail("circles must be a list of {x, y, radius}");
    for (std::size_t i = 0; i < circles->size(); ++i) {
      const std::string name = "circles[" + std::to_string(i) + "]";
      const json& c = (*circles)[i];
      const json *x = member(c, "x"), *y = member(c, "y"), *r = member(c, "radius");
      if (!x || !y || !r || c.size() != 3) fail(name + " must be {x, y, radius} [m]");
      core::Obstacle circle;
      circle.x = number(*x, name + "/x");
      circle.y = number(*y, name + "/y");
      circle.radius = number(*r, name + "/radius");
      out.boundary.circles.push_back(circle);
      out.circle_names.push_back(name);
    }
  }
}

std::string nameOr(const std::vector<std::string>& names, std::size_t i, const char* kind) {
  return i < names.size() ? names[i] : std::string(kind) + " " + std::to_string(i);
}

}  // namespace

std::string checkFieldBoundary(const core::FieldBoundary& field, const std::vector<std::string>& void_names,
                               const std::vector<std::string>& circle_names) {
  const auto ringError = [](const Ring& ring, const std::string& name) -> std::string {
    if (ring.size() < 3) return name + " has " + std::to_string(ring.size()) + " vertices; a polygon needs at least 3";
    for (std::size_t i = 0; i < ring.size(); ++i)
      if (!ring[i].allFinite()) return name + " vertex " + std::to_string(i) + " must be finite";
    const std::string shape = core::ringProblem(ring);
    return shape.empty() ? "" : name + " " + shape;
  };
  std::string e = ringError(field.outer, "the field boundary");
  if (!e.empty()) return e;
  for (std::size_t i = 0; i < field.voids.size(); ++i) {
    const std::string name = nameOr(void_names, i, "void");
    e = ringError(field.voids[i], name);
    if (!e.empty()) return e;
    if (!core::ringCoveredBy(field.voids[i], field.outer))
      return name +
             (core::ringsOverlap(field.voids[i], field.outer) ? " crosses the field boundary"
                                                              : " lies outside the field boundary") +
             "; a void must lie inside it";
  }
  for (std::size_t i = 0; i < field.circles.size(); ++i) {
    const core::Obstacle& c = field.circles[i];
    const std::string name = nameOr(circle_names, i, "circle");
    if (!std::isfinite(c.x) || !std::isfinite(c.y)) return name + " centre must be finite";
    if (!(std::isfinite(c.radius) && c.radius > 0.0))
      return name + " radius = " + core::formatNumber(c.radius) + " m must be > 0";
    const Eigen::Vector2d centre(c.x, c.y);
    if (!core::circleCoveredBy(centre, c.radius, field.outer))
      return name +
             (core::circleOverlapsRing(centre, c.radius, field.outer) ? " crosses the field boundary"
                                                                      : " lies outside the field boundary") +
             " (centre (" + core::formatNumber(c.x) + ", " + core::formatNumber(c.y) + ") m, radius " +
             core::formatNumber(c.radius) + " m); a void must lie inside it";
  }
  return "";
}

FieldFile readFieldFile(const std::string& path, const std::optional<GeoOrigin>& origin) {
  FieldFile out;
  try {
    const json root = parseFile(path, readText(path));
    if (!root.is_object()) fail("the file must hold an object (GeoJSON or a local-frame field), not a list or value");
    if (const json* frame = member(root, "frame")) {
      if (*frame != "local") fail("frame must be \"local\" (a WGS84 field is GeoJSON)");
      readLocal(root, out);
    } else {
      readGeoJson(root, origin, out);
    }
    const std::string e = checkFieldBoundary(out.boundary, out.void_names, out.circle_names);
    if (!e.empty()) fail(e);
  } catch (const FileError& e) {
    throw std::invalid_argument(path + ": " + e.what());
  } catch (const json::exception& e) {  // a value of an unexpected type the checks above did not catch
    throw std::invalid_argument(path + ": " + e.what());
  }
  return out;
}

core::FieldBoundary loadFieldBoundary(const std::string& path, const std::optional<GeoOrigin>& origin) {
  return readFieldFile(path, origin).boundary;
}

}  // namespace field_file
}  // namespace sowing_robot
