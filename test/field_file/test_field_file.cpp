// Field files (include/sowing_robot/field_file/field_file.h): GeoJSON in WGS84 projected to the local ENU frame
// against GeographicLib's own LocalCartesian, boundaries, holes and voids as the file marks them, the local-frame
// format, every refusal as one line naming the problem, the example fields of config/fields/ and the field_info
// command.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <GeographicLib/LocalCartesian.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sowing_robot/core/common/polygon.h"
#include "sowing_robot/field_file/field_file.h"

using namespace sowing_robot;
namespace fs = std::filesystem;

namespace {

const field_file::GeoOrigin kOrigin{48.4125, 11.7283, 460.0};

/// lon/lat of a local point (GeographicLib's reverse at the origin's height): how the tests write WGS84 files.
std::pair<double, double> lonLat(double x, double y) {
  GeographicLib::LocalCartesian lc(kOrigin.latitude, kOrigin.longitude, kOrigin.altitude);
  double lat = 0.0, lon = 0.0, h = 0.0;
  lc.Reverse(x, y, 0.0, lat, lon, h);
  return {lon, lat};
}

/// A number as the test files write it (10 decimals of a degree, about 10 µm) and read back.
double written(double degrees) {
  char b[32];
  std::snprintf(b, sizeof(b), "%.10f", degrees);
  return std::stod(b);
}

std::string position(double x, double y) {
  const auto [lon, lat] = lonLat(x, y);
  char b[64];
  std::snprintf(b, sizeof(b), "[%.10f, %.10f]", lon, lat);
  return b;
}

/// A closed GeoJSON ring of local points.
std::string ring(const std::vector<std::pair<double, double>>& pts) {
  std::string s = "[";
  for (const auto& [x, y] : pts) s += position(x, y) + ", ";
  return s + position(pts[0].first, pts[0].second) + "]";
}

std::string feature(const std::string& properties, const std::string& type, const std::string& coordinates) {
  return R"({"type": "Feature", "properties": )" + properties + R"(, "geometry": {"type": ")" + type +
         R"(", "coordinates": )" + coordinates + "}}";
}

std::string collection(const std::vector<std::string>& features, bool origin = true) {
  std::string s = R"({"type": "FeatureCollection", )";
  if (origin) s += R"("origin": {"lat": 48.4125, "lon": 11.7283, "alt": 460.0}, )";
  s += R"("features": [)";
  for (std::size_t i = 0; i < features.size(); ++i) s += (i ? ", " : "") + features[i];
  return s + "]}";
}

const std::vector<std::pair<double, double>> kSquare{{0, 0}, {100, 0}, {100, 100}, {0, 100}};

class FieldFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sowing_field_file_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  /// The one-line error of loading `text` (as file `name`), "" when it loads.
  std::string refusal(const std::string& text, const std::string& name = "f.geojson",
                      const std::optional<field_file::GeoOrigin>& origin = std::nullopt) {
    const std::string path = write(name, text);
    try {
      field_file::loadFieldBoundary(path, origin);
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << "not one line: " << what;
      return what.substr(path.size() + 2);
    }
    return "";
  }
  fs::path dir_;
};

void expectHas(const std::string& text, const std::string& part) {
  EXPECT_NE(text.find(part), std::string::npos) << "'" << text << "' should say '" << part << "'";
}

}  // namespace

// The origin is (0, 0); a point 100 m north (by GeographicLib's reverse) comes back as (0, 100) within 1 mm; every
// vertex as GeographicLib's forward gives it for the position in the file (to 1 nm: the same computation).
TEST_F(FieldFile, Wgs84RoundTripAgainstGeographicLib) {
  const std::string path =
      write("square.geojson", collection({feature(R"({"role": "boundary"})", "Polygon", "[" + ring(kSquare) + "]")}));
  const core::FieldBoundary f = field_file::loadFieldBoundary(path);
  ASSERT_EQ(f.outer.size(), 4u);  // the closing position is dropped
  EXPECT_NEAR(f.outer[0].x(), 0.0, 1e-6);
  EXPECT_NEAR(f.outer[0].y(), 0.0, 1e-6);
  EXPECT_NEAR(f.outer[3].x(), 0.0, 1e-3);
  EXPECT_NEAR(f.outer[3].y(), 100.0, 1e-3);
  GeographicLib::LocalCartesian lc(kOrigin.latitude, kOrigin.longitude, kOrigin.altitude);
  for (std::size_t i = 0; i < kSquare.size(); ++i) {
    const auto [lon, lat] = lonLat(kSquare[i].first, kSquare[i].second);
    double x = 0.0, y = 0.0, z = 0.0;
    lc.Forward(written(lat), written(lon), kOrigin.altitude, x, y, z);  // the position the file holds
    EXPECT_NEAR(f.outer[i].x(), x, 1e-9) << i;
    EXPECT_NEAR(f.outer[i].y(), y, 1e-9) << i;
    EXPECT_NEAR(f.outer[i].x(), kSquare[i].first, 1e-3) << i;
    EXPECT_NEAR(f.outer[i].y(), kSquare[i].second, 1e-3) << i;
  }
  // Every edge keeps its length and direction (a 100 m side stays 100 m within 1 mm).
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d edge = f.outer[(i + 1) % 4] - f.outer[i];
    const Eigen::Vector2d want(kSquare[(i + 1) % 4].first - kSquare[i].first,
                               kSquare[(i + 1) % 4].second - kSquare[i].second);
    EXPECT_NEAR((edge - want).norm(), 0.0, 1e-3) << "edge " << i;
  }
  EXPECT_NEAR(core::ringArea(f.outer), 1e4, 0.5);
}

// The caller's origin takes the place of the file's; without either a WGS84 file is refused.
TEST_F(FieldFile, OriginFromTheCallerOrTheFile) {
  const std::string body = "[" + ring(kSquare) + "]";
  EXPECT_EQ(refusal(collection({feature("{}", "Polygon", body)}, false), "a.geojson", kOrigin), "");
  expectHas(refusal(collection({feature("{}", "Polygon", body)}, false)), "WGS84 coordinates without an origin");
  // An origin 100 m further north moves the field 100 m south in the local frame.
  field_file::GeoOrigin north = kOrigin;
  {
    const auto [lon, lat] = lonLat(0.0, 100.0);
    north.latitude = lat;
    north.longitude = lon;
  }
  const std::string path = write("b.geojson", collection({feature("{}", "Polygon", body)}));
  const field_file::FieldFile f = field_file::readFieldFile(path, north);
  EXPECT_EQ(f.origin_source, "the caller");
  EXPECT_NEAR(f.boundary.outer[0].y(), -100.0, 1e-2);
  EXPECT_EQ(field_file::readFieldFile(path).origin_source, "the file");
  expectHas(refusal(R"({"type": "Polygon", "origin": {"lat": 91, "lon": 0}, "coordinates": [[[0,0],[1,0],[1,1]]]})"),
            "origin lat 91 is outside [-90, 90]");
}

// Voids: features marked "void" (a Polygon, a MultiPolygon, a Point with a radius) and the boundary's holes. The
// boundary is the feature marked "boundary", wherever it is listed; unmarked features are not the field's.
TEST_F(FieldFile, HolesAndVoidFeatures) {
  const std::string hole = ring({{10, 10}, {10, 20}, {20, 20}, {20, 10}});
  const std::string path = write(
      "voids.geojson",
      collection(
          {feature(R"({"name": "pond", "role": "void"})", "Polygon", "[" + ring({{50, 50}, {60, 50}, {55, 60}}) + "]"),
           feature(R"({"name": "track"})", "Polygon", "[" + ring({{500, 500}, {600, 500}, {550, 600}}) + "]"),
           feature(R"({"role": "boundary"})", "Polygon", "[" + ring(kSquare) + ", " + hole + "]"),
           feature(R"({"name": "pole", "role": "void", "radius": 1.5})", "Point", position(80, 30)),
           feature(
               R"({"role": "void"})", "MultiPolygon",
               "[[" + ring({{30, 70}, {35, 70}, {35, 75}}) + "], [" + ring({{70, 70}, {75, 70}, {75, 75}}) + "]]")}));
  const field_file::FieldFile f = field_file::readFieldFile(path);
  ASSERT_EQ(f.boundary.voids.size(), 4u);
  EXPECT_EQ(f.void_names[0], "features[2] hole 1");  // the boundary's hole first
  EXPECT_EQ(f.void_names[1], "features[0] 'pond'");
  EXPECT_EQ(f.void_names[2], "features[4] polygon 0");
  EXPECT_NEAR(core::ringArea(f.boundary.voids[0]), 100.0, 0.01);
  EXPECT_NEAR(core::ringArea(f.boundary.voids[1]), 50.0, 0.01);
  ASSERT_EQ(f.boundary.circles.size(), 1u);
  EXPECT_NEAR(f.boundary.circles[0].x, 80.0, 1e-3);
  EXPECT_NEAR(f.boundary.circles[0].y, 30.0, 1e-3);
  EXPECT_EQ(f.boundary.circles[0].radius, 1.5);
  EXPECT_EQ(f.circle_names[0], "features[3] 'pole'");
  // A bare Polygon (no features, no role) is the boundary, its holes the voids.
  const field_file::FieldFile bare = field_file::readFieldFile(
      write("bare.geojson", R"({"type": "Polygon", "coordinates": [)" + ring(kSquare) + ", " + hole + "]}"), kOrigin);
  EXPECT_EQ(bare.boundary.voids.size(), 1u);
}

TEST_F(FieldFile, LocalFrameYamlAndJson) {
  const std::string yaml =
      write("f.yaml",
            "frame: local\nboundary: [[0, 0], [50, 0], [50, 40], [0, 40]]\n"
            "voids:\n  - [[10, 10], [20, 10], [20, 20]]\ncircles:\n  - {x: 30, y: 30, radius: 2}\n");
  const core::FieldBoundary f = field_file::loadFieldBoundary(yaml, kOrigin);  // the origin is not used
  EXPECT_EQ(f.outer[2], Eigen::Vector2d(50, 40));
  ASSERT_EQ(f.voids.size(), 1u);
  ASSERT_EQ(f.circles.size(), 1u);
  EXPECT_EQ(f.circles[0].radius, 2.0);
  const std::string json =
      write("f.json", R"({"frame": "local", "boundary": [[0, 0], [50, 0], [50, 40], [0, 40], [0, 0]]})");
  EXPECT_EQ(field_file::loadFieldBoundary(json).outer.size(), 4u);
  expectHas(refusal("frame: local\nboundary: [[0, 0], [50, 0], [50, .nan]]\n", "n.yaml"),
            "boundary[2] y = nan must be finite");
  expectHas(refusal("frame: local\nboundary: [[0, 0], [50, 0], [50, 40]]\nvoid: []\n", "k.yaml"), "unknown key 'void'");
  expectHas(
      refusal("frame: local\nboundary: [[0, 0], [50, 0], [50, 40]]\ncircles: [{x: 30, y: 10, radius: 0}]\n", "r.yaml"),
      "circles[0] radius = 0 m must be > 0");
  expectHas(refusal("frame: local\nvoids: []\n", "nb.yaml"), "no field boundary");
  expectHas(refusal("frame: [unclosed\n", "bad.yaml"), "not YAML (line");
}

// Every refusal is one line "PATH: what", naming what is wrong.
TEST_F(FieldFile, RefusalsNameTheProblem) {
  try {
    field_file::loadFieldBoundary((dir_ / "missing.geojson").string());
    ADD_FAILURE() << "a missing file loaded";
  } catch (const std::invalid_argument& e) {
    expectHas(e.what(), "missing.geojson: cannot read the file: No such file or directory");
  }
  expectHas(refusal("{\"type\": \"FeatureCollection\", "), "not JSON (parse error");
  expectHas(refusal(R"({"type": "LineString", "coordinates": []})"), "GeoJSON type 'LineString' holds no field");
  expectHas(refusal(collection({feature(R"({"role": "void"})", "Polygon", "[" + ring(kSquare) + "]")})),
            "no field boundary");
  expectHas(refusal(collection({feature("{}", "Polygon", "[[" + position(0, 0) + ", " + position(1, 0) + "]]")})),
            "features[0] outer ring has 2 distinct vertices; a polygon needs at least 3");
  expectHas(refusal(collection({feature("{}", "Polygon", "[[[0, 0], [1, 95], [1, 1], [0, 0]]]")})),
            "features[0] outer ring[1] latitude 95 is outside [-90, 90]");
  expectHas(refusal(collection({feature("{}", "Polygon", "[[[0, 0], [181, 1], [1, 1], [0, 0]]]")})),
            "longitude 181 is outside [-180, 180]");
  expectHas(refusal(collection({feature("{}", "Polygon", "[[[0, 0], [1e999, 1], [1, 1], [0, 0]]]")})),
            "not JSON (number overflow");  // JSON has no infinity: the parser refuses it (YAML's .nan: above)
  // A bow-tie boundary, named with Boost.Geometry's reason.
  expectHas(refusal(collection({feature("{}", "Polygon", "[" + ring({{0, 0}, {100, 100}, {100, 0}, {0, 100}}) + "]")})),
            "the field boundary crosses itself (");
  // A bow-tie void; a void outside; a void across the edge; a circle across the edge; a Point without a radius.
  const std::string boundary = feature(R"({"role": "boundary"})", "Polygon", "[" + ring(kSquare) + "]");
  expectHas(refusal(collection({boundary, feature(R"({"name": "pond", "role": "void"})", "Polygon",
                                                  "[" + ring({{10, 10}, {20, 20}, {20, 10}, {10, 20}}) + "]")})),
            "features[1] 'pond' crosses itself");
  expectHas(refusal(collection({boundary, feature(R"({"role": "void"})", "Polygon",
                                                  "[" + ring({{200, 10}, {220, 10}, {220, 20}}) + "]")})),
            "features[1] lies outside the field boundary");
  expectHas(refusal(collection({boundary, feature(R"({"role": "void"})", "Polygon",
                                                  "[" + ring({{90, 10}, {120, 10}, {120, 20}}) + "]")})),
            "features[1] crosses the field boundary");
  expectHas(refusal(collection({boundary, feature(R"({"role": "void", "radius": 3})", "Point", position(99, 50))})),
            "features[1] crosses the field boundary");
  expectHas(refusal(collection({boundary, feature(R"({"role": "void", "radius": -1})", "Point", position(50, 50))})),
            "features[1] radius = -1 m must be > 0");
  expectHas(refusal(collection({boundary, feature(R"({"role": "void"})", "Point", position(50, 50))})),
            "a Point void needs a \"radius\"");
  expectHas(refusal(collection({boundary, boundary})), "a second feature with \"role\": \"boundary\"");
  expectHas(refusal(collection({feature(R"({"role": "field"})", "Polygon", "[" + ring(kSquare) + "]")})),
            "\"role\" must be \"boundary\" or \"void\"");
  // A hole outside its polygon is a void outside the field.
  expectHas(refusal(collection({feature(
                "{}", "Polygon", "[" + ring(kSquare) + ", " + ring({{200, 200}, {210, 200}, {210, 210}}) + "]")})),
            "features[0] hole 1 lies outside the field boundary");
}

TEST(FieldFileCheck, CheckFieldBoundaryInTheLocalFrame) {
  core::FieldBoundary f;
  f.outer = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  EXPECT_EQ(field_file::checkFieldBoundary(f), "");
  f.voids.push_back({{1, 1}, {2, 2}, {3, 3}});
  EXPECT_EQ(field_file::checkFieldBoundary(f), "void 0 has zero area (its vertices lie on one line or point)");
  f.voids.clear();
  f.circles.push_back({5, 5, 5.0});  // touches the edge from inside: allowed
  EXPECT_EQ(field_file::checkFieldBoundary(f), "");
  f.circles[0].radius = 5.5;
  EXPECT_NE(field_file::checkFieldBoundary(f).find("circle 0 crosses the field boundary"), std::string::npos);
}

// The example fields load: config/fields/l_field.geojson (an L of about 1 ha with a pond and a pole, the same field
// in the local frame as l_field_local.yaml) and long_field.geojson (about 10 ha, a tree clump as its hole).
TEST(FieldFileExamples, ConfigFieldsLoad) {
  const std::string dir = std::string(SOWING_SOURCE_DIR) + "/config/fields/";
  const field_file::FieldFile l = field_file::readFieldFile(dir + "l_field.geojson");
  EXPECT_EQ(l.boundary.outer.size(), 6u);
  EXPECT_NEAR(core::ringArea(l.boundary.outer), 1e4, 500.0);
  EXPECT_EQ(l.boundary.voids.size(), 1u);
  EXPECT_EQ(l.boundary.circles.size(), 1u);
  const core::FieldBoundary local = field_file::loadFieldBoundary(dir + "l_field_local.yaml");
  ASSERT_EQ(local.outer.size(), l.boundary.outer.size());
  for (std::size_t i = 0; i < local.outer.size(); ++i)
    EXPECT_NEAR((local.outer[i] - l.boundary.outer[i]).norm(), 0.0, 1e-3) << i;
  EXPECT_NEAR(local.circles[0].x, l.boundary.circles[0].x, 1e-3);
  const core::FieldBoundary big = field_file::loadFieldBoundary(dir + "long_field.geojson");
  EXPECT_NEAR(core::ringArea(big.outer), 1e5, 5e3);
  EXPECT_EQ(big.voids.size(), 1u);
}

namespace {
struct Outcome {
  int status = -1;
  std::string out, err;
};
std::string readAll(const fs::path& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
Outcome fieldInfo(const std::string& args) {
  const fs::path dir = fs::temp_directory_path() / ("sowing_field_info_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string line = std::string(SOWING_FIELD_INFO_BIN) + " " + args + " > " + (dir / "out").string() + " 2> " +
                           (dir / "err").string() + " < /dev/null";
  const int raw = std::system(line.c_str());
  Outcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.out = readAll(dir / "out");
  o.err = readAll(dir / "err");
  fs::remove_all(dir);
  return o;
}
}  // namespace

TEST(FieldInfo, PrintsAreasOrOneLineWithExitTwo) {
  const std::string dir = std::string(SOWING_SOURCE_DIR) + "/config/fields/";
  Outcome o = fieldInfo(dir + "l_field.geojson");
  EXPECT_EQ(o.status, 0) << o.err;
  expectHas(o.out, "from the file");
  expectHas(o.out, "boundary: 6 vertices, area ");
  expectHas(o.out, "bounding box: x ");
  expectHas(o.out, "void features[1] 'pond'");
  expectHas(o.out, "void features[2] 'power pole': circle at (95.00, 30.00) m, radius 1.20 m");
  o = fieldInfo(dir + "long_field.geojson --origin 48.419,11.742");
  EXPECT_EQ(o.status, 0) << o.err;
  expectHas(o.out, "from the caller");
  o = fieldInfo(dir + "no_such_field.geojson");
  EXPECT_EQ(o.status, 2);
  EXPECT_EQ(o.err.rfind("field_info: ", 0), 0u) << o.err;
  EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "not one line:\n" << o.err;
  expectHas(o.err, "cannot read the file");
  o = fieldInfo(dir + "l_field.geojson --origin 95,0");
  EXPECT_EQ(o.status, 2);
  expectHas(o.err, "off the Earth");
}
