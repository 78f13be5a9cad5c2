// The `benchmark` command (src/tools/benchmark.cpp) through its executable: bad requests give one error line,
// exit != 0 and no report; the files it writes are the same byte for byte whatever --threads.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <string>

#include "../common/test_files.h"

using sowing_robot::test::exists;
using sowing_robot::test::readFile;
using sowing_robot::test::TempDir;

namespace {
const std::string kSource = SOWING_SOURCE_DIR;
const std::string kBin = SOWING_BENCHMARK_BIN;

struct Outcome {
  int status = -1;
  std::string err;
};

/// Runs the command with `args` (its stdout discarded), capturing stderr.
Outcome run(const TempDir& dir, const std::string& args) {
  const std::string err = dir.path + "/stderr.txt";
  const int raw = std::system((kBin + " " + args + " > /dev/null 2> " + err).c_str());
  Outcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.err = readFile(err);
  return o;
}

/// A 3 s thesis line (the suite's file, shortened) in DIR/quick_line.yaml.
std::string quickLine(const TempDir& dir) {
  std::string text = readFile(kSource + "/config/scenarios/thesis_line.yaml");
  text = std::regex_replace(text, std::regex("name: thesis_line"), "name: quick_line");
  text = std::regex_replace(text, std::regex("duration: 25.0"), "duration: 3.0");
  text = std::regex_replace(text, std::regex("settle_time: 15.0"), "settle_time: 2.0");
  const std::string path = dir.path + "/quick_line.yaml";
  std::ofstream(path) << text;
  return path;
}

void expectOneLineRefusal(const TempDir& dir, const std::string& args, const std::string& needle) {
  SCOPED_TRACE(args);
  const std::string out = dir.path + "/out";
  const Outcome o = run(dir, args + " --output " + out);
  EXPECT_NE(o.status, 0);
  EXPECT_NE(o.err.find(needle), std::string::npos) << o.err;
  EXPECT_EQ(o.err.rfind("benchmark: ", 0), 0u) << o.err;
  ASSERT_FALSE(o.err.empty());
  EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "more than one line: " << o.err;
  EXPECT_FALSE(exists(out + "/report.md"));
  EXPECT_FALSE(exists(out + "/runs.csv"));
}
}  // namespace

TEST(BenchmarkCommand, BadRequestsGiveOneLineAndNoReport) {
  TempDir dir;
  const std::string line = quickLine(dir);
  // The same request done right works (so each refusal below is the edit's).
  const Outcome ok = run(dir, "--scenarios " + line + " --controllers kanayama+atsmc --seeds 2 --threads 1 --output " +
                                  dir.path + "/good");
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_TRUE(exists(dir.path + "/good/report.md"));
  expectOneLineRefusal(dir, "--scenarios no_such_scenario --controllers kanayama+atsmc --seeds 2",
                       "unknown scenario 'no_such_scenario'");
  expectOneLineRefusal(dir, "--scenarios " + line + " --controllers kanayama+smc --seeds 2", "smc");
  expectOneLineRefusal(dir, "--scenarios " + line + " --controllers kanayama+atsmc --seeds 0", "--seeds must be >= 1");
  std::string typo = readFile(line);
  typo.replace(typo.find("  noise_std:"), 12, "  noise_sdt:");
  std::ofstream(dir.path + "/quick_line.yaml") << typo;
  expectOneLineRefusal(dir, "--scenarios " + line + " --controllers kanayama+atsmc --seeds 2", "noise_sdt");
  // A draw range the file's checks accept but the plant refuses for some seeds (mass_scale above 10).
  std::string heavy = readFile(quickLine(dir));
  heavy.replace(heavy.find("mass_scale: [0.8, 1.5]"), 22, "mass_scale: [5.0, 20.0]");
  std::ofstream(dir.path + "/quick_line.yaml") << heavy;
  expectOneLineRefusal(dir, "--scenarios " + line + " --controllers kanayama+atsmc --seeds 20",
                       "a drawn run does not validate");
}

TEST(BenchmarkCommand, TheFilesDoNotDependOnTheThreadCount) {
  TempDir dir;
  const std::string line = quickLine(dir);
  const std::string args = "--scenarios " + line + " --controllers kanayama+atsmc,rpp+pid --seeds 5 --output ";
  ASSERT_EQ(run(dir, args + dir.path + "/one --threads 1").status, 0);
  ASSERT_EQ(run(dir, args + dir.path + "/two --threads 2").status, 0);
  for (const char* f : {"/runs.csv", "/envelopes.csv", "/report.md"}) {
    const std::string a = readFile(dir.path + "/one" + f), b = readFile(dir.path + "/two" + f);
    EXPECT_FALSE(a.empty()) << f;
    EXPECT_EQ(a, b) << f;
  }
  // 2 controllers x 5 seeds, one header line.
  const std::string csv = readFile(dir.path + "/one/runs.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 11);
}

// --profile NAME as sim.launch profile:=NAME: the package's config/profiles/NAME.yaml with its gains
// config/tuned/NAME/, the same runs as the file's path with --tuned-dir; an unknown name is refused with one line
// that lists the available profiles, exit 2 (as every bad request).
TEST(BenchmarkCommand, AProfileIsChosenByNameAndBringsItsGains) {
  TempDir dir;
  const std::string args = "--scenarios wet_line --controllers rpp+pid --seeds 2 --threads 1 --output ";
  Outcome o = run(dir, args + dir.path + "/by_name --profile field");
  ASSERT_EQ(o.status, 0) << o.err;
  o = run(dir, args + dir.path + "/by_path --profile " + kSource + "/config/profiles/field.yaml --tuned-dir " +
                   kSource + "/config/tuned/field");
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string by_name = readFile(dir.path + "/by_name/runs.csv");
  EXPECT_FALSE(by_name.empty());
  EXPECT_EQ(by_name, readFile(dir.path + "/by_path/runs.csv"));
  // The report says where the gains came from: the profile's own.
  const std::string report = readFile(dir.path + "/by_name/report.md");
  EXPECT_NE(report.find("- rpp+pid: " + kSource + "/config/tuned/field/rpp+pid.yaml"), std::string::npos) << report;
  EXPECT_NE(report.find("Profile: `field`"), std::string::npos) << report;
  // An explicit --tuned-dir still wins over the profile's gains.
  o = run(dir, args + dir.path + "/own_gains --profile field --tuned-dir " + dir.path);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(readFile(dir.path + "/own_gains/report.md").find("- rpp+pid: the parameter tables' defaults"),
            std::string::npos);

  const std::string out = dir.path + "/nosuch";
  o = run(dir, args + out + " --profile nosuch");
  EXPECT_EQ(o.status, 2);
  const std::string refusal = "benchmark: unknown profile 'nosuch' (available in " + kSource + "/config/profiles: ";
  EXPECT_EQ(o.err.rfind(refusal, 0), 0u) << o.err;
  EXPECT_NE(o.err.find("field", refusal.size()), std::string::npos) << o.err;
  EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "more than one line: " << o.err;
  EXPECT_FALSE(exists(out + "/runs.csv"));
}

// The evaluation protocol (docs/evaluation.md): every run carries its scenario's set in runs.csv and the report,
// and a scenario labelled test whose content a validation scenario holds (the thesis line under another name,
// shortened) is refused with one line naming what it shares, before any run.
TEST(BenchmarkCommand, RunsCarryTheirSetAndAnOverlappingTestScenarioIsRefused) {
  TempDir dir;
  const std::string line = quickLine(dir);
  ASSERT_EQ(run(dir, "--scenarios " + line + " --seeds 2 --threads 1 --output " + dir.path + "/val").status, 0);
  const std::string csv = readFile(dir.path + "/val/runs.csv");
  EXPECT_EQ(csv.rfind("scenario,set,controller,seed,", 0), 0u) << csv;
  EXPECT_NE(csv.find("\nquick_line,validation,kanayama+atsmc,0,"), std::string::npos) << csv;
  const std::string report = readFile(dir.path + "/val/report.md");
  EXPECT_NE(report.find("- **quick_line** [validation]"), std::string::npos) << report;
  EXPECT_NE(report.find("- validation: quick_line (content "), std::string::npos) << report;

  std::string text = readFile(line);
  text.replace(text.find("\nset: validation"), 16, "\nset: test");
  std::ofstream(line) << text;
  expectOneLineRefusal(dir, "--scenarios " + line + " --seeds 2",
                       "thesis_line (validation): same layout, soil and draws");
  expectOneLineRefusal(dir, "--scenarios " + line + " --seeds 2", "test scenario quick_line is not held out");
  // Its own base seed makes the draws its own, but the world is still the thesis line's.
  expectOneLineRefusal(dir, "--scenarios " + line + " --seeds 2 --base-seed 77",
                       "thesis_line (validation): same layout and soil (other draws)");
}
