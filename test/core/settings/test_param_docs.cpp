// docs/parameters.md and the comments of config/*.yaml come from the parameter tables: this fails when
// either is out of step (run `param_docs --markdown > docs/parameters.md` and `param_docs --sync
// config/*.yaml` after changing a table), when a YAML key is no parameter, or a value is out of range.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "sowing_robot/core/control/sliding_mode.h"
#include "sowing_robot/core/settings/param_catalog.h"

using namespace sowing_robot::core;

namespace {
std::string readFile(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
const std::filesystem::path kSource(SOWING_SOURCE_DIR);
}  // namespace

TEST(ParamDocs, ParametersMarkdownIsGeneratedFromTheTables) {
  EXPECT_EQ(readFile(kSource / "docs" / "parameters.md"), parametersMarkdown())
      << "docs/parameters.md is stale: rosrun sowing_robot param_docs --markdown > docs/parameters.md";
}

TEST(ParamDocs, EveryConfigCommentComesFromTheTables) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kSource / "config")) {
    if (entry.path().extension() != ".yaml") continue;
    ++files;
    const std::string text = readFile(entry.path());
    std::vector<std::string> problems;
    const std::string synced = syncYamlComments(text, entry.path().filename().string(), problems);
    for (const auto& p : problems) ADD_FAILURE() << p;
    EXPECT_EQ(text, synced) << entry.path() << " has comments out of step with the tables: "
                            << "rosrun sowing_robot param_docs --sync config/*.yaml";
  }
  EXPECT_GE(files, 6);
}

TEST(ParamDocs, SyncRefusesAnUnknownKeyAndAnOutOfRangeValue) {
  std::vector<std::string> problems;
  syncYamlComments("torque_controller:\n  k1: -1.0\n  k9: 2.0\n", "x.yaml", problems);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("k1 = -1.0 must be finite and > 0"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("torque_controller/k9 is no parameter"), std::string::npos) << problems[1];
}

TEST(ParamDocs, SyncRewritesTheCommentAndKeepsTheValue) {
  std::vector<std::string> problems;
  const std::string out = syncYamlComments(
      "torque_controller:\n  k2: 570.0   # old text\n"
      "              # old continuation\n  eta1: 2.0\n",
      "x.yaml", problems);
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(out,
            "torque_controller:\n  k2: 570.0                 # feedback gain K2 [N·m·s/rad] (> 0, default 150.0)\n"
            "  eta1: 2.0                 # switching gain eta1 [N·m] (>= 0, default 2.0)\n");
}

TEST(ParamTable, DefaultsComeFromTheTable) {
  const SlidingModeParams p;
  EXPECT_EQ(p.k2, std::get<double>(slidingModeTable().find("k2")->info.default_value));
  EXPECT_EQ(p.switching.type, SwitchType::Sign);
  EXPECT_TRUE(p.adaptive);
  EXPECT_EQ(p.validate(), "");
}
