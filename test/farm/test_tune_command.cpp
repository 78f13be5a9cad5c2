// The `tune` command through its executable: threads and MPI ranks (mpirun -np 1, 2, 4,
// oversubscribed) give the same gains bit for bit; a run stopped after iteration K, or killed with SIGKILL
// at any moment, and resumed gives the gains of an uninterrupted one; a rank that dies ends the job with
// a message within seconds and the checkpoint resumes; bad input gives one line.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "../common/test_files.h"

using sowing_robot::test::exists;
using sowing_robot::test::readFile;
using sowing_robot::test::TempDir;

namespace {
const std::string kSource = SOWING_SOURCE_DIR;
const std::string kTune = SOWING_TUNE_BIN;
const std::string kMpirun = SOWING_MPIEXEC;
const std::string kSmall = kSource + "/test/farm/tune_small.yaml";
const std::string kLong = kSource + "/test/farm/tune_kill.yaml";
const std::string kBenchmark = SOWING_BENCHMARK_BIN;

struct Outcome {
  int status = -1;
  std::string err;
  double seconds = 0.0;
};

/// Runs `command` through the shell, stdout discarded, stderr captured.
Outcome shell(const TempDir& dir, const std::string& command) {
  const std::string err = dir / "stderr.txt";
  const auto t0 = std::chrono::steady_clock::now();
  const int raw = std::system((command + " > /dev/null 2> " + err).c_str());
  Outcome o;
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.err = readFile(err);
  return o;
}

std::string tune(const std::string& args) { return kTune + " " + args; }
std::string mpi(int ranks, const std::string& args, const std::string& env = "") {
  return kMpirun + " --allow-run-as-root --oversubscribe " + env + " -np " + std::to_string(ranks) + " " + kTune + " " +
         args;
}

/// The gains file without its "# run:" line (date, wall time, ranks: the only lines two equal runs may differ in).
std::string gains(const std::string& path) {
  std::istringstream in(readFile(path));
  std::string line, out;
  while (std::getline(in, line))
    if (line.rfind("# run:", 0) != 0) out += line + "\n";
  return out;
}

/// The search's iteration recorded in a checkpoint (-1 if none is readable yet).
int checkpointIteration(const std::string& path) {
  const std::string text = readFile(path);
  const auto at = text.find("\niteration ");
  return at == std::string::npos ? -1 : std::atoi(text.c_str() + at + 11);
}

std::string reference(const TempDir& dir, const std::string& config) {
  const std::string out = dir / "reference.yaml";
  const Outcome o = shell(dir, tune("--config " + config + " --threads 2 --output " + out));
  EXPECT_EQ(o.status, 0) << o.err;
  const std::string g = gains(out);
  EXPECT_NE(g.find("kinematic_controller:"), std::string::npos);
  return g;
}

}  // namespace

TEST(TuneCommand, ThreadCountsGiveTheSameGains) {
  TempDir dir;
  const std::string ref = reference(dir, kSmall);
  for (int t : {1, 3}) {
    const Outcome o =
        shell(dir, tune("--config " + kSmall + " --threads " + std::to_string(t) + " --output " + (dir / "t.yaml")));
    ASSERT_EQ(o.status, 0) << o.err;
    EXPECT_EQ(ref, gains(dir / "t.yaml")) << t << " threads";
  }
}

TEST(TuneCommand, MpiRanksGiveTheThreadedGainsBitForBit) {
  TempDir dir;
  const std::string ref = reference(dir, kSmall);
  for (int n : {1, 2, 4}) {
    const std::string out = dir / ("np" + std::to_string(n) + ".yaml");
    const Outcome o = shell(dir, mpi(n, "--config " + kSmall + " --output " + out));
    ASSERT_EQ(o.status, 0) << o.err;
    EXPECT_EQ(ref, gains(out)) << "mpirun -np " << n;
    EXPECT_NE(readFile(out).find("MPI, " + std::to_string(n) + " rank"), std::string::npos);
  }
}

TEST(TuneCommand, StoppedAfterIterationKAndResumedEqualsUninterrupted) {
  TempDir dir;
  const std::string ref = reference(dir, kSmall);
  for (int k : {0, 2, 5}) {
    SCOPED_TRACE("stopped after iteration " + std::to_string(k));
    const std::string ckpt = dir / ("k" + std::to_string(k) + ".ckpt"), out = dir / "resumed.yaml";
    const std::string csv = dir / "progress.csv";
    std::remove(out.c_str());
    Outcome o = shell(dir, tune("--config " + kSmall + " --checkpoint " + ckpt + " --progress " + csv + " --output " +
                                out + " --stop-after " + std::to_string(k)));
    ASSERT_EQ(o.status, 3) << o.err;
    EXPECT_FALSE(exists(out));
    EXPECT_EQ(checkpointIteration(ckpt), k + 1);
    // Resumed under another evaluator count: threads, or 2 MPI ranks.
    o = shell(dir, k == 2 ? mpi(2, "--config " + kSmall + " --checkpoint " + ckpt + " --resume --progress " + csv +
                                       " --output " + out)
                          : tune("--config " + kSmall + " --checkpoint " + ckpt + " --resume --progress " + csv +
                                 " --output " + out));
    ASSERT_EQ(o.status, 0) << o.err;
    EXPECT_NE(o.err.find("resuming from"), std::string::npos) << o.err;
    EXPECT_EQ(ref, gains(out));
    // One CSV row per iteration, 0..6, once each.
    const std::string rows = readFile(csv);
    for (int i = 0; i <= 6; ++i) EXPECT_NE(rows.find("\n" + std::to_string(i) + ","), std::string::npos) << rows;
    EXPECT_EQ(std::count(rows.begin(), rows.end(), '\n'), 8) << rows;
  }
}

TEST(TuneCommand, KilledWithSigkillAndResumedEqualsUninterrupted) {
  TempDir dir;
  const std::string ref = reference(dir, kLong);
  // Kill points: a fixed early moment (maybe before the first checkpoint), and as soon as the checkpoint
  // shows iteration 3 and iteration 6 (the kill lands while the next iteration runs or is being written).
  for (int point : {-1, 3, 6}) {
    SCOPED_TRACE("kill point " + std::to_string(point));
    const std::string ckpt = dir / ("kill" + std::to_string(point + 1) + ".ckpt"), out = dir / "killed.yaml";
    std::remove(out.c_str());
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      std::freopen("/dev/null", "w", stderr);
      ::execl(kTune.c_str(), kTune.c_str(), "--config", kLong.c_str(), "--checkpoint", ckpt.c_str(), "--output",
              out.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    const auto t0 = std::chrono::steady_clock::now();
    if (point < 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(80));
    } else {
      while (checkpointIteration(ckpt) < point && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(30))
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ASSERT_EQ(::kill(pid, SIGKILL), 0);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the run ended before it was killed: make tune_kill.yaml longer";
    EXPECT_FALSE(exists(out));
    const Outcome o =
        shell(dir, tune("--config " + kLong + " --threads 2 --checkpoint " + ckpt + " --resume --output " + out));
    ASSERT_EQ(o.status, 0) << o.err;
    EXPECT_EQ(ref, gains(out));
  }
}

TEST(TuneCommand, ADeadRankEndsTheJobQuicklyAndTheCheckpointResumes) {
  TempDir dir;
  const std::string ref = reference(dir, kSmall);
  const std::string ckpt = dir / "dead.ckpt", out = dir / "dead.yaml";
  // Rank 1 kills itself (SIGKILL) at its 8th evaluation: in iteration 1 or 2.
  Outcome o = shell(dir, mpi(2, "--config " + kSmall + " --checkpoint " + ckpt + " --output " + out,
                             "-x SOWING_FARM_TEST_DIE_AFTER=8"));
  EXPECT_NE(o.status, 0);
  EXPECT_LT(o.seconds, 20.0) << "a dead rank must end the job, not hang it";
  EXPECT_FALSE(exists(out));
  EXPECT_GE(checkpointIteration(ckpt), 1) << o.err;
  o = shell(dir, mpi(2, "--config " + kSmall + " --checkpoint " + ckpt + " --resume --output " + out));
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(ref, gains(out));
}

TEST(TuneCommand, BadInputGivesOneLine) {
  TempDir dir;
  auto oneLine = [](const Outcome& o) {
    EXPECT_EQ(o.status, 2);
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
    EXPECT_EQ(o.err.rfind("tune: ", 0), 0u) << o.err;
  };
  oneLine(shell(dir, tune("--config " + (dir / "missing.yaml"))));
  oneLine(shell(dir, tune("--config " + kSmall + " --resume")));
  oneLine(shell(dir, tune("--bogus 1")));
  std::ofstream(dir / "typo.yaml") << "pso_tuner:\n  particels: 3\n";
  oneLine(shell(dir, tune("--config " + (dir / "typo.yaml"))));
  // A checkpoint of another config, and a damaged one.
  const std::string ckpt = dir / "c.ckpt";
  ASSERT_EQ(shell(dir, tune("--config " + kSmall + " --checkpoint " + ckpt + " --stop-after 1")).status, 3);
  std::string other = readFile(kSmall);
  other.replace(other.find("seed: 5"), 7, "seed: 6");
  std::ofstream(dir / "other.yaml") << other;
  Outcome o = shell(dir, tune("--config " + (dir / "other.yaml") + " --checkpoint " + ckpt + " --resume"));
  oneLine(o);
  EXPECT_NE(o.err.find("another setup"), std::string::npos) << o.err;
  std::string text = readFile(ckpt);
  text[text.size() / 2] = text[text.size() / 2] == '1' ? '2' : '1';
  std::ofstream(ckpt, std::ios::trunc) << text;
  o = shell(dir, tune("--config " + kSmall + " --checkpoint " + ckpt + " --resume"));
  oneLine(o);
  EXPECT_NE(o.err.find("checksum"), std::string::npos) << o.err;
}

// Robust tuning through the command: --controller picks the pair, the gains file records
// its training set, and MPI ranks (each training run its own task) give the threaded gains bit for bit.
TEST(TuneCommand, RobustTuningOnRanksGivesTheThreadedGainsAndRecordsItsTrainingSet) {
  TempDir dir;
  const std::string config = kSource + "/test/farm/tune_robust_small.yaml";
  const std::string threaded = dir / "threads.yaml";
  Outcome o = shell(dir, tune("--config " + config + " --controller kanayama+pid --threads 2 --output " + threaded));
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string ref = gains(threaded);
  EXPECT_NE(ref.find("# training: robust_line runs 3 base_seed 11\n"), std::string::npos) << ref;
  EXPECT_NE(ref.find("kp:"), std::string::npos) << "--controller kanayama+pid tunes the PID, not the file's ATSMC";
  const std::string ranks = dir / "np2.yaml";
  o = shell(dir, mpi(2, "--config " + config + " --controller kanayama+pid --output " + ranks));
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(ref, gains(ranks));
  // robust/profile by name (the package's config/profiles/field.yaml): the same gains as by the file's path.
  std::string by_name = readFile(config);
  by_name.replace(by_name.find("profile: ../../config/profiles/field.yaml"), 41, "profile: field");
  by_name.replace(by_name.find("scenario: robust_line.yaml"), 26,
                  "scenario: " + kSource + "/test/farm/robust_line.yaml");
  std::ofstream(dir / "by_name.yaml") << by_name;
  const std::string named = dir / "by_name_gains.yaml";
  o = shell(dir,
            tune("--config " + (dir / "by_name.yaml") + " --controller kanayama+pid --threads 2 --output " + named));
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string from_name = gains(named);  // all but its "# config:" line
  EXPECT_EQ(ref.substr(ref.find("# scenario:")), from_name.substr(from_name.find("# scenario:")));
  // A robust file that also sets the line scenario's keys is refused with one line.
  std::ofstream(dir / "both.yaml") << readFile(config) << "scenario:\n  start: {x: 0.0}\n";
  o = shell(dir, tune("--config " + (dir / "both.yaml")));
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.err.find("not used with robust"), std::string::npos) << o.err;
}

// The benchmark's Monte-Carlo runs on the farm: the files are those of the threaded runner, byte for byte.
TEST(BenchmarkCommand, MpiRanksWriteTheThreadedFilesByteForByte) {
  TempDir dir;
  const std::string args = " --scenarios thesis_line,sine_rows --controllers kanayama+atsmc,rpp+pid --seeds 4";
  Outcome o = shell(dir, kBenchmark + args + " --threads 2 --output " + (dir / "threads"));
  ASSERT_EQ(o.status, 0) << o.err;
  for (int n : {2, 3}) {
    const std::string out = dir / ("np" + std::to_string(n));
    o = shell(dir, kMpirun + " --allow-run-as-root --oversubscribe -np " + std::to_string(n) + " " + kBenchmark + args +
                       " --output " + out);
    ASSERT_EQ(o.status, 0) << o.err;
    for (const char* f : {"runs.csv", "envelopes.csv", "report.md"})
      EXPECT_EQ(readFile(dir / "threads/" + f), readFile(out + "/" + f)) << f << ", mpirun -np " << n;
  }
}
