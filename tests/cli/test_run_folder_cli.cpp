// `drover run`'s run folder: checked before any work, written as OUT.partial and swapped in when complete, so a kill
// while writing leaves an earlier run whole and no new folder that looks finished; SIGINT/SIGTERM stop the reading
// and the run writes the sweeps it processed, saying so in report.json; report.json says why every run ended.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "io/trajectory_io.hpp"
#include "support/cli.hpp"
#include "support/cli_process.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;
using Json = nlohmann::json;

// Every file of a folder with its bytes.
std::map<std::string, std::string> contentsOf(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) files[e.path().filename().string()] = readText(e.path());
  return files;
}

// A 60 s straight course (600 sweeps), simulated once: long enough to signal a run part-way. The LIS runs it at
// ~12-20x real time, so the first progress line (2 s of wall time) comes 40-70 % in; at 20 s it came at 85-96 %,
// and a faster LIS or machine finished the course before the signal.
class RunFolder : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();
    sim_ = runDrover("sim -q --scenario straight --duration 60 --no-camera --out " + data().string());
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override { ASSERT_EQ(sim_.exit_code, 0) << sim_.output; }
  static fs::path data() { return *dir_ / "straight60"; }
  static std::string run(const fs::path& out, const std::string& extra = "") {
    return "run " + data().string() + " --format sim --config " + std::string(DROVER_SOURCE_DIR) +
           "/config/farm_sim.yaml --out " + out.string() + (extra.empty() ? "" : " " + extra);
  }

  static inline std::unique_ptr<TempDir> dir_;
  static inline CliResult sim_;
};

TEST_F(RunFolder, AKillWhileWritingLeavesTheEarlierRunWholeAndNoNewFolderThatLooksFinished) {
  TempDir dir;
  const fs::path out = dir / "run", partial = dir / "run.partial";
  const CliResult earlier = runDrover(run(out, "--duration 1 -q"));
  ASSERT_EQ(earlier.exit_code, 0) << earlier.output;
  const std::map<std::string, std::string> before = contentsOf(out);
  ASSERT_TRUE(before.count("report.json"));

  DroverProcess p(run(out, "--duration 3"), dir / "log.txt");
  ASSERT_TRUE(p.started());
  // Kill it as soon as it starts writing its outputs.
  const bool writing = p.waitUntil([&] { return fs::exists(partial / ".drover-partial"); });
  p.signal(SIGKILL);
  const int status = p.wait();
  ASSERT_TRUE(writing) << "the run never wrote into " << partial << ":\n" << p.log();
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << p.log();

  EXPECT_EQ(contentsOf(out), before) << "the earlier run must stay whole and unmixed";
  EXPECT_TRUE(fs::exists(partial / ".drover-partial")) << "the leftover is marked as an unfinished run";

  // The next run removes the leftover and replaces the earlier run.
  const CliResult next = runDrover(run(out, "--duration 2 -q"));
  ASSERT_EQ(next.exit_code, 0) << next.output;
  EXPECT_FALSE(fs::exists(partial));
  EXPECT_NE(readText(out / "report.json"), before.at("report.json"));
  EXPECT_FALSE(fs::exists(out / ".drover-partial"));
}

TEST_F(RunFolder, SigintStopsTheReadingAndWritesACompleteFolderWhoseReportSaysSo) {
  TempDir dir;
  const fs::path out = dir / "run";
  DroverProcess p(run(out), dir / "log.txt");
  ASSERT_TRUE(p.started());
  // The first progress line comes after 2 s of wall time, part-way through the course.
  ASSERT_TRUE(p.waitUntil([&] { return p.logContains("run: scan"); })) << p.log();
  p.signal(SIGINT);
  const int status = p.wait();
  ASSERT_TRUE(WIFEXITED(status)) << p.log();
  EXPECT_EQ(WEXITSTATUS(status), 130) << "128 + SIGINT, as a shell reports it:\n" << p.log();
  EXPECT_TRUE(contains(p.log(), "interrupted by SIGINT")) << p.log();

  const Json report = readJson(out / "report.json");
  EXPECT_EQ(report["end"]["reason"], "interrupted by SIGINT");
  EXPECT_EQ(report["end"]["interrupted"], true);
  const Trajectory est = io::readTum((out / "trajectory.tum").string());
  EXPECT_GT(est.size(), 0u);
  EXPECT_LT(est.size(), 570u) << "stopped before the end of the 600 sweeps";
  EXPECT_EQ(readJsonLines(out / "sweeps.jsonl").size(), est.size()) << "every line whole, the streamed file closed";
  for (const char* f : {"keyframes.tum", "map.pcd", "map.ply", "trajectory_imu_rate.tum"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  EXPECT_FALSE(fs::exists(dir / "run.partial"));
}

TEST_F(RunFolder, ASecondSignalKillsAtOnceLeavingNoRunFolder) {
  TempDir dir;
  const fs::path out = dir / "run";
  DroverProcess p(run(out), dir / "log.txt");
  ASSERT_TRUE(p.started());
  ASSERT_TRUE(p.waitUntil([&] { return p.logContains("run: scan"); })) << p.log();
  // Whichever of the two the kernel delivers first asks the run to stop; the other kills it, before it wrote.
  p.signal(SIGTERM);
  p.signal(SIGINT);
  const int status = p.wait();
  ASSERT_TRUE(WIFSIGNALED(status)) << "exited with " << WEXITSTATUS(status) << ":\n" << p.log();
  EXPECT_TRUE(WTERMSIG(status) == SIGINT || WTERMSIG(status) == SIGTERM) << WTERMSIG(status);
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(RunFolder, TheReportSaysWhetherTheDataOrADurationLimitEndedTheRun) {
  TempDir dir;
  const CliResult limited = runDrover(run(dir / "limited", "--duration 1 -q"));
  ASSERT_EQ(limited.exit_code, 0) << limited.output;
  EXPECT_EQ(readJson(dir / "limited" / "report.json")["end"]["reason"], "--duration reached");
  const CliResult tail = runDrover(run(dir / "tail", "--start 18.5 -q"));
  ASSERT_EQ(tail.exit_code, 0) << tail.output;
  const Json end = readJson(dir / "tail" / "report.json")["end"];
  EXPECT_EQ(end["reason"], "end of data");
  EXPECT_EQ(end["interrupted"], false);
}

TEST(RunFolderKitti, TheReportSaysAMaxFramesLimitEndedTheRun) {
  const fs::path seq = sharedData("kitti/sequences/00");
  DROVER_REQUIRE_SHARED(seq / "velodyne" / "000002.bin");
  TempDir dir;
  const CliResult r = runDrover("run " + seq.string() + " --format kitti --config " + std::string(DROVER_SOURCE_DIR) +
                                "/config/kitti.yaml --max-frames 3 -q --out " + (dir / "o").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(readJson(dir / "o" / "report.json")["end"]["reason"], "--max-frames reached");
}

// ------------------------------------------------------------------------ refused before any work

// One `[error] OUT (--out): ...` line containing WHY and exit code 2, before the dataset was opened.
void expectRefused(const CliResult& r, const std::string& out, const std::string& why) {
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_EQ(r.output.rfind("[error] " + out + " (--out): ", 0), 0u) << r.output;
  EXPECT_TRUE(contains(r.output, why)) << why << " missing from: " << r.output;
}

TEST_F(RunFolder, AnOutFolderHoldingOtherFilesIsRefusedAndKept) {
  TempDir dir;
  writeText(dir / "mine" / "notes.txt", "mine");
  writeText(dir / "mine" / "report.json", "{}");
  const std::string mine = (dir / "mine").string();
  expectRefused(runDrover(run(dir / "mine")), mine, "holds notes.txt, which drover run does not write");
  fs::remove(dir / "mine" / "notes.txt");
  expectRefused(runDrover(run(dir / "mine")), mine, "holds a report.json that drover run did not write");
  writeText(dir / "half" / "trajectory.tum", "");
  expectRefused(runDrover(run(dir / "half")), (dir / "half").string(), "is not an earlier run folder (no report.json)");
  EXPECT_EQ(readText(dir / "mine" / "report.json"), "{}");
}

TEST_F(RunFolder, AnOutThatIsAFileOrUnderAFileIsRefused) {
  TempDir dir;
  writeText(dir / "file", "mine");
  expectRefused(runDrover(run(dir / "file")), (dir / "file").string(), "is a file, not a folder");
  expectRefused(runDrover(run(dir / "file" / "run")), (dir / "file" / "run").string(), "is not a folder");
  EXPECT_EQ(readText(dir / "file"), "mine");
}

TEST_F(RunFolder, TheWorkingFolderAndItsParentAreNeverRunFolders) {
  TempDir dir;
  fs::create_directories(dir / "empty" / "cwd");
  expectRefused(runDroverIn(dir / "empty" / "cwd", run(".")), ".", "is the working folder");
  expectRefused(runDroverIn(dir / "empty" / "cwd", run("..")), "..", "is an ancestor of the working folder");
  EXPECT_TRUE(fs::is_empty(dir / "empty" / "cwd"));
}

TEST_F(RunFolder, AnEmptyFolderBecomesTheRunFolder) {
  TempDir dir;
  fs::create_directories(dir / "empty");
  const CliResult r = runDrover(run(dir / "empty", "--duration 1 -q"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "empty" / "report.json"));
}

}  // namespace
}  // namespace drover::test
