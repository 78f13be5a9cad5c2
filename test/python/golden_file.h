// The check of a golden file written by the C++ core for the Python tests (metrics_golden, pairs_golden):
// the file must equal what the core computes now, line by line, so a failure names the first differing
// record; SOWING_WRITE_GOLDEN=1 rewrites it instead (a deliberate change of the core's numbers).
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

/// `what` says what changed in the failure message ("metrics", "runs").
inline void expectGoldenFile(const std::string& now, const char* path, const char* what) {
  if (const char* w = std::getenv("SOWING_WRITE_GOLDEN"); w && std::string(w) == "1") {
    std::ofstream(path) << now;
    GTEST_SKIP() << "rewrote " << path;
  }
  std::ifstream f(path);
  ASSERT_TRUE(f) << "cannot read " << path;
  std::stringstream file;
  file << f.rdbuf();
  std::istringstream a(now), b(file.str());
  std::string la, lb;
  for (int line = 1; std::getline(a, la); ++line) {
    ASSERT_TRUE(static_cast<bool>(std::getline(b, lb))) << path << " ends at line " << line;
    ASSERT_EQ(la, lb) << path << ":" << line << ": the core's " << what
                      << " changed; if deliberately, rewrite it (SOWING_WRITE_GOLDEN=1)";
  }
  EXPECT_FALSE(static_cast<bool>(std::getline(b, lb))) << path << " has extra lines";
}
