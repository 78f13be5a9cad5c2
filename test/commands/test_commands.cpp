// Every command answers --help and names an unknown option: the C++ programs through their
// built executables (the ROS nodes with no master), the scripts through their paths in the source tree.
//   cmd --help, cmd -h        exit 0, the usage on stdout, before any work
//   cmd --no-such-option      exit 2, one line on stderr that names the option and points to --help
// The lists below are checked against src/nodes/, src/tools/ and scripts/: a new command must join them.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {
const std::string kSource = SOWING_SOURCE_DIR;
const std::string kBin = SOWING_BIN_DIR;

const std::vector<std::string> kPrograms{"benchmark",
                                         "run_scenario",
                                         "param_docs",
                                         "bag_recorder",
                                         "plant_sim",
                                         "kinematic_controller",
                                         "torque_controller",
                                         "reference_generator",
                                         "run_monitor",
                                         "seed_drill",
                                         "state_estimator",
                                         "pso_tuner",
                                         "tune",
                                         "cmd_vel_limiter",
                                         "fleet_monitor",
                                         "seed_map",
                                         "field_info",
                                         "sow_field"};
const std::vector<std::string> kScripts{"run",
                                        "test",
                                        "sim",
                                        "setup",
                                        "analyze_bag",
                                        "benchmark_plots",
                                        "tune_pairs",
                                        "farm",
                                        "dev/bench",
                                        "dev/soak",
                                        "dev/format",
                                        "dev/tune_wide_bounds",
                                        "dev/field_evidence",
                                        "dev/drive_train_evidence",
                                        "dev/field_evidence_figure",
                                        "dev/reproduce",
                                        "dev/benchmark_report",
                                        "dev/path_evidence",
                                        "dev/seed_evidence",
                                        "dev/seed_evidence_table",
                                        "dev/recording_sizes",
                                        "dev/fleet_figures"};

struct Outcome {
  int status = -1;
  std::string out, err;
};

std::string readFile(const fs::path& path) {
  std::ifstream f(path);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// Runs `command args` with the system python3 first on PATH and no reachable ROS master.
Outcome run(const std::string& command, const std::string& args) {
  const fs::path dir = fs::temp_directory_path() / ("sowing_commands_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string line = "PATH=/usr/bin:/bin:$PATH ROS_MASTER_URI=http://127.0.0.1:9 timeout 60 " + command + " " +
                           args + " > " + (dir / "out").string() + " 2> " + (dir / "err").string() + " < /dev/null";
  const int raw = std::system(line.c_str());
  Outcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.out = readFile(dir / "out");
  o.err = readFile(dir / "err");
  fs::remove_all(dir);
  return o;
}

std::string path(const std::string& name) {
  return std::find(kPrograms.begin(), kPrograms.end(), name) != kPrograms.end() ? kBin + "/" + name
                                                                                : kSource + "/scripts/" + name;
}

std::vector<std::string> allCommands() {
  std::vector<std::string> all = kPrograms;
  all.insert(all.end(), kScripts.begin(), kScripts.end());
  return all;
}

class Command : public ::testing::TestWithParam<std::string> {};

TEST_P(Command, HelpPrintsUsageAndExitsZero) {
  for (const char* flag : {"--help", "-h"}) {
    SCOPED_TRACE(GetParam() + " " + std::string(flag));
    const Outcome o = run(path(GetParam()), flag);
    EXPECT_EQ(o.status, 0) << o.err;
    EXPECT_NE(lower(o.out).find("usage"), std::string::npos) << "stdout:\n" << o.out << "\nstderr:\n" << o.err;
  }
}

TEST_P(Command, UnknownOptionIsOneLineAndExitTwo) {
  const Outcome o = run(path(GetParam()), "--no-such-option");
  EXPECT_EQ(o.status, 2) << o.err;
  ASSERT_FALSE(o.err.empty());
  EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "more than one line:\n" << o.err;
  EXPECT_NE(o.err.find("unknown option '--no-such-option'"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("--help"), std::string::npos) << o.err;
}

std::string testName(const ::testing::TestParamInfo<std::string>& info) {
  std::string n = info.param;
  std::replace(n.begin(), n.end(), '/', '_');
  return n;
}

INSTANTIATE_TEST_SUITE_P(AllCommands, Command, ::testing::ValuesIn(allCommands()), testName);

// A node's --help among the arguments roslaunch passes (__name:=, __log:=, remappings) still answers, and
// those arguments are not taken for unknown options.
TEST(NodeArguments, RosArgumentsPassWithHelp) {
  const Outcome o = run(path("kinematic_controller"), "__name:=kc __log:=/tmp/kc.log feedback:=odom _gain:=1 --help");
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("usage: rosrun sowing_robot kinematic_controller"), std::string::npos) << o.out;
}

TEST(CommandLists, CoverEveryProgramAndScript) {
  std::set<std::string> programs, scripts;
  // The ROS mains (src/nodes/<name>_node.cpp) and the command-line tools (src/tools/<name>.cpp).
  for (const std::string dir : {"/src/nodes", "/src/tools"}) {
    for (const auto& e : fs::directory_iterator(kSource + dir)) {
      std::string stem = e.path().stem().string();
      const std::string suffix = "_node";
      if (stem.size() > suffix.size() && stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0)
        stem.resize(stem.size() - suffix.size());
      programs.insert(stem);
    }
  }
  for (const std::string dir : {std::string(), std::string("dev/")})
    for (const auto& e : fs::directory_iterator(kSource + "/scripts/" + dir))
      if (e.is_regular_file() && (e.status().permissions() & fs::perms::owner_exec) != fs::perms::none)
        scripts.insert(dir + e.path().filename().string());
  EXPECT_EQ(programs, std::set<std::string>(kPrograms.begin(), kPrograms.end()));
  EXPECT_EQ(scripts, std::set<std::string>(kScripts.begin(), kScripts.end()));
}
}  // namespace
