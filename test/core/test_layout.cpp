// The core's rooms and the direction of their includes (docs/design.md): a file of one room may include
// the headers of its own room and of the rooms below it, never of a room above or beside it, and nothing
// outside the core (ROS, the scenario loader). Read from the sources, so a new include against the
// direction fails here before it can knot the rooms together.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const fs::path kRoot = SOWING_SOURCE_DIR;

/// Each room and the rooms it may include (besides itself).
const std::map<std::string, std::set<std::string>>& allowedIncludes() {
  static const std::map<std::string, std::set<std::string>> m = [] {
    const std::set<std::string> base{"numerics", "common"};
    std::set<std::string> behaviour = base;
    behaviour.insert("model");
    std::set<std::string> top = behaviour;
    top.insert({"control", "planning", "estimation"});
    std::set<std::string> evaluation = top;
    evaluation.insert("simulation");
    return std::map<std::string, std::set<std::string>>{
        {"numerics", {}},       {"common", {"numerics"}}, {"model", base},
        {"control", behaviour}, {"planning", behaviour},  {"estimation", behaviour},
        {"simulation", top},    {"settings", top},        {"evaluation", evaluation},
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
  const std::regex include_line(R"re(^\s*#\s*include\s*"sowing_robot/([^"]+)")re");
  const std::regex core_header(R"re(core/([a-z_]+)/[a-z0-9_]+\.h)re");
  int includes_seen = 0;
  for (const auto& [path, room] : coreFiles(outside)) {
    std::ifstream in(path);
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
      ++line_no;
      std::smatch m;
      if (!std::regex_search(line, m, include_line)) continue;
      ++includes_seen;
      const std::string target = m[1];
      const std::string where = path.string() + ":" + std::to_string(line_no) + ": ";
      std::smatch h;
      if (!std::regex_match(target, h, core_header)) {
        ADD_FAILURE() << where << "the core includes \"sowing_robot/" << target << "\", outside the core's rooms";
        continue;
      }
      const std::string to = h[1];
      const auto it = allowedIncludes().find(room);
      if (to == room || it == allowedIncludes().end()) continue;
      EXPECT_TRUE(it->second.count(to)) << where << room << " includes " << to << " (against the direction)";
    }
  }
  EXPECT_GT(includes_seen, 100);
}

// The test's own rule, on a made-up include against the direction: model may not include planning.
TEST(Layout, TheRuleRefusesAnIncludeUpward) {
  EXPECT_FALSE(allowedIncludes().at("model").count("planning"));
  EXPECT_FALSE(allowedIncludes().at("control").count("simulation"));
  EXPECT_TRUE(allowedIncludes().at("evaluation").count("simulation"));
}
