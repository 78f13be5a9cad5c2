// The core's rooms and the direction of their includes (docs/design.md): a file of one room may include
// the headers of its own room and of the rooms below it, never of a room above or beside it, and nothing
// outside the core (ROS, the scenario loader). Read from the sources, so a new include against the
// direction fails here before it can knot the rooms together. The package's own headers are included as
// "sowing_robot/core/<room>/<file>.h" only: an angle-bracket form (<sowing_robot/...>) or a relative one
// ("../x.h", "sensors.h") would hide the room it reaches, so each is refused too; and the core's only
// other includes are the C++17 standard library, Eigen, Boost.Geometry (header-only: the coverage planner's
// polygons; it has no catkin include path) and Boost's header-only circular_buffer (the EKF's history).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const fs::path kRoot = SOWING_SOURCE_DIR;

/// Each room and the rooms it may include (besides itself).
const std::map<std::string, std::set<std::string>>& allowedIncludes() {
  static const std::map<std::string, std::set<std::string>> m = [] {
    const std::set<std::string> base{"common"};
    std::set<std::string> behaviour = base;
    behaviour.insert("model");
    std::set<std::string> top = behaviour;
    top.insert({"control", "planning", "estimation"});
    std::set<std::string> evaluation = top;
    evaluation.insert("simulation");
    return std::map<std::string, std::set<std::string>>{
        {"common", {}},
        {"model", base},
        {"control", behaviour},
        {"planning", behaviour},
        {"estimation", behaviour},
        {"simulation", top},
        {"settings", top},
        {"evaluation", evaluation},
    };
  }();
  return m;
}

/// The core's files: include/sowing_robot/core/<room>/*.h and src/core/<room>/*.cpp, with their room.
std::vector<std::pair<fs::path, std::string>> coreFiles(std::vector<std::string>& outside_rooms) {
  std::vector<std::pair<fs::path, std::string>> files;
  for (const fs::path& dir : {kRoot / "include/sowing_robot/core", kRoot / "src/core"}) {
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      if (!entry.is_regular_file()) continue;
      const fs::path rel = fs::relative(entry.path(), dir);
      if (std::distance(rel.begin(), rel.end()) != 2) {
        outside_rooms.push_back(entry.path().string());
        continue;
      }
      files.emplace_back(entry.path(), rel.begin()->string());
    }
  }
  return files;
}

/// What one file's includes break, one line of text per include ("<path>:<line>: <what>"), for a file of
/// `room` with the contents `text`; `includes` (if given) counts the include lines read.
std::vector<std::string> layoutViolations(const fs::path& path, const std::string& room, const std::string& text,
                                          int* includes = nullptr) {
  // Either delimiter, so that an angle-bracket include of the package is seen (and refused) too.
  static const std::regex include_line(R"re(^\s*#\s*include\s*([<"])([^>"]+)[>"])re");
  static const std::regex core_header(R"re(sowing_robot/core/([a-z_]+)/[a-z0-9_]+\.h)re");
  // <vector>, <cmath>, ...: the standard library's headers have neither a directory nor an extension.
  static const std::regex standard_header(R"re([a-z_]+)re");
  static const std::regex eigen_header(R"re((Eigen|unsupported/Eigen)/[A-Za-z0-9_/]+)re");
  static const std::regex geometry_header(R"re(boost/(geometry(\.hpp|/[A-Za-z0-9_/]+\.hpp)|circular_buffer\.hpp))re");
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::smatch m;
    if (!std::regex_search(line, m, include_line)) continue;
    if (includes) ++*includes;
    const bool angle = m[1] == "<";
    const std::string target = m[2];
    const std::string where = path.string() + ":" + std::to_string(line_no) + ": ";
    const bool own = target.rfind("sowing_robot/", 0) == 0;
    if (!own) {
      if (!angle)
        out.push_back(where + "relative include \"" + target +
                      "\": the package's headers are included as \"sowing_robot/core/<room>/<file>.h\"");
      else if (!std::regex_match(target, standard_header) && !std::regex_match(target, eigen_header) &&
               !std::regex_match(target, geometry_header))
        out.push_back(where + "the core includes <" + target +
                      ">, outside its dependencies (the C++17 standard library, Eigen, Boost.Geometry and "
                      "boost/circular_buffer.hpp)");
      continue;
    }
    if (angle) out.push_back(where + "<" + target + "> in angle brackets: the package's own headers go in quotes");
    std::smatch h;
    if (!std::regex_match(target, h, core_header)) {
      out.push_back(where + "the core includes \"" + target + "\", outside the core's rooms");
      continue;
    }
    const std::string to = h[1];
    const auto it = allowedIncludes().find(room);
    if (to == room || it == allowedIncludes().end()) continue;
    if (!it->second.count(to)) out.push_back(where + room + " includes " + to + " (against the direction)");
  }
  return out;
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(Layout, EveryCoreFileLivesInARoom) {
  std::vector<std::string> outside;
  const auto files = coreFiles(outside);
  EXPECT_GT(files.size(), 50u);
  for (const std::string& f : outside) ADD_FAILURE() << f << " is not in a room folder (core/<room>/<file>)";
  for (const auto& [path, room] : files)
    EXPECT_TRUE(allowedIncludes().count(room)) << path << ": '" << room << "' is not a room of docs/design.md";
}

TEST(Layout, IncludesRunOneWayBetweenTheRooms) {
  std::vector<std::string> outside;
  int includes_seen = 0;
  for (const auto& [path, room] : coreFiles(outside))
    for (const std::string& v : layoutViolations(path, room, readFile(path), &includes_seen)) ADD_FAILURE() << v;
  EXPECT_GT(includes_seen, 100);
}

// The test's own rule, on a made-up include against the direction: model may not include planning.
TEST(Layout, TheRuleRefusesAnIncludeUpward) {
  EXPECT_FALSE(allowedIncludes().at("model").count("planning"));
  EXPECT_FALSE(allowedIncludes().at("control").count("simulation"));
  EXPECT_TRUE(allowedIncludes().at("evaluation").count("simulation"));
}

// The checker itself, fed made-up files: each kind of bad include is reported (once, on its line), and a
// file that keeps the rules is clean.
namespace {
const fs::path kFake = "include/sowing_robot/core/model/fake.h";

void expectOneViolation(const std::string& text, int line, const std::string& what) {
  const std::vector<std::string> v = layoutViolations(kFake, "model", text);
  ASSERT_EQ(v.size(), 1u) << text;
  EXPECT_EQ(v[0].rfind(kFake.string() + ":" + std::to_string(line) + ": ", 0), 0u) << v[0];
  EXPECT_NE(v[0].find(what), std::string::npos) << v[0];
}
}  // namespace

TEST(Layout, TheCheckerPassesAFileThatKeepsTheRules) {
  const std::string clean =
      "// a model header\n#pragma once\n#include <Eigen/Core>\n#include <vector>\n\n"
      "#include \"sowing_robot/core/common/types.h\"\n#include \"sowing_robot/core/model/plant.h\"\n"
      "#include \"sowing_robot/core/common/validation.h\"\n// #include \"sowing_robot/core/planning/field.h\"\n";
  int includes = 0;
  EXPECT_EQ(layoutViolations(kFake, "model", clean, &includes), std::vector<std::string>{});
  EXPECT_EQ(includes, 5);
}

TEST(Layout, TheCheckerReportsAnIncludeAgainstTheDirection) {
  expectOneViolation("#include <vector>\n#include \"sowing_robot/core/planning/field.h\"\n", 2,
                     "model includes planning (against the direction)");
  expectOneViolation("#include \"sowing_robot/core/control/controllers.h\"\n", 1, "model includes control");
  expectOneViolation("  #  include \"sowing_robot/core/evaluation/pso.h\"\n", 1, "model includes evaluation");
}

TEST(Layout, TheCheckerReportsTheOwnHeadersInAngleBrackets) {
  expectOneViolation("#include <sowing_robot/core/common/types.h>\n", 1, "in angle brackets");
  // Against the direction as well: both are reported.
  const auto v = layoutViolations(kFake, "model", "#include <sowing_robot/core/simulation/runner.h>\n");
  ASSERT_EQ(v.size(), 2u);
  EXPECT_NE(v[0].find("in angle brackets"), std::string::npos) << v[0];
  EXPECT_NE(v[1].find("model includes simulation"), std::string::npos) << v[1];
}

TEST(Layout, TheCheckerReportsRelativeIncludes) {
  expectOneViolation("#include \"../planning/field.h\"\n", 1, "relative include \"../planning/field.h\"");
  expectOneViolation("#include <cmath>\n#include \"sensors.h\"\n", 2, "relative include \"sensors.h\"");
  expectOneViolation("#include \"core/common/types.h\"\n", 1, "relative include");
}

TEST(Layout, TheCheckerReportsIncludesFromOutsideTheCore) {
  expectOneViolation("#include <ros/ros.h>\n", 1, "<ros/ros.h>, outside its dependencies");
  expectOneViolation("#include <nav_msgs/Odometry.h>\n", 1, "outside its dependencies");
  expectOneViolation("#include <boost/asio.hpp>\n", 1, "outside its dependencies");
  EXPECT_EQ(
      layoutViolations(kFake, "model", "#include <boost/geometry.hpp>\n#include <boost/geometry/io/wkt/wkt.hpp>\n"),
      std::vector<std::string>{});
  expectOneViolation("#include \"sowing_robot/ros/seed_drill.h\"\n", 1, "outside the core's rooms");
  expectOneViolation("#include \"sowing_robot/WheelTorque.h\"\n", 1, "outside the core's rooms");
}
