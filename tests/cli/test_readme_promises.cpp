// README.md's promises about bad data -- what is dropped, what is skipped with a warning, what is an error, what
// never happens -- each as a test through the binary. Every test quotes the sentence it checks. The fixtures are
// written here (tests/fuzz/fixtures.hpp) or by `drover sim`, so no shared data is needed.
#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz/fixtures.hpp"
#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;
using fuzz::hallScan;
using fuzz::writeKittiSequence;

std::vector<std::string> taggedLines(const std::string& output, const std::string& tag) {
  std::vector<std::string> out;
  std::istringstream in(output);
  for (std::string l; std::getline(in, l);)
    if (contains(l, tag)) out.push_back(l);
  return out;
}

std::size_t fileLineCount(const fs::path& p) {
  std::ifstream in(p);
  std::size_t n = 0;
  for (std::string l; std::getline(in, l);) n += !l.empty() && l[0] != '#';  // data lines, not the header
  return n;
}

// One [error] line naming `names`, exit 2.
void expectOneErrorNaming(const CliResult& r, const std::string& names) {
  EXPECT_EQ(r.exit_code, 2) << r.output;
  const auto errors = taggedLines(r.output, "[error]");
  ASSERT_EQ(errors.size(), 1u) << r.output;
  EXPECT_TRUE(contains(errors[0], names)) << "the error should name " << names << ": " << errors[0];
}

// A 6-frame KITTI odometry sequence (box-shaped hall, 64 x 360 rays) under dir/00.
fs::path kittiSequence(const TempDir& dir) {
  writeKittiSequence(dir / "00", 6, 64, 360);
  return dir / "00";
}

std::string runKittiSequence(const fs::path& seq, const fs::path& out) {
  return "run " + seq.string() + " --format kitti --config " + config("kitti.yaml") + " --out " + out.string();
}

// "Every command prints one line `[error] FILE (RECORD): what is wrong` and exits with code 2 on bad input"
TEST(ReadmePromises, EveryCommandReportsAMissingInputInOneErrorLineWithExitCode2) {
  TempDir dir;
  const std::string none = (dir / "none").string();
  for (const std::string& args :
       {"info " + none + " --format kitti", "sim --scenario straight --config " + none + ".yaml --out " + none,
        "run " + none + " --format kitti --out " + (dir / "r").string(), "eval ape " + none + " " + none,
        "loop pair " + none + " " + none, "loop eval " + none + " --format kitti",
        "graph optimize " + none + " " + (dir / "o.g2o").string(), "features detect --detector orb " + none,
        "features track " + none + " --format euroc --out " + (dir / "t").string()}) {
    SCOPED_TRACE(args);
    expectOneErrorNaming(runDrover(args), none);
  }
}

// "`-q` prints only errors."
TEST(ReadmePromises, QuietPrintsNothingOnGoodInputForEveryCommand) {
  TempDir dir;
  const fs::path seq = kittiSequence(dir);
  fuzz::writeTrajectories(dir / "traj");
  fuzz::writeG2oGraph(dir / "g.g2o");
  fuzz::writeTexturedPng(dir / "board.png", 96, 64, 1);
  const std::string tum = (dir / "traj" / "traj.tum").string(), scan = (seq / "velodyne" / "000000.bin").string();
  for (const std::string& args :
       {"info " + seq.string() + " --format kitti -q",
        "sim --scenario straight --duration 0.5 --camera-rate 10 --out " + (dir / "sim").string() + " -q",
        runKittiSequence(seq, dir / "run") + " --max-frames 2 -q", "eval ape " + tum + " " + tum + " -q",
        "loop pair " + scan + " " + scan + " -q", "loop eval " + seq.string() + " --format kitti -q",
        "graph optimize " + (dir / "g.g2o").string() + " " + (dir / "o.g2o").string() + " -q",
        "features detect --detector orb " + (dir / "board.png").string() + " -q",
        "features track " + (dir / "sim").string() + " --format sim --detector orb --out " + (dir / "t").string() +
            " -q"}) {
    SCOPED_TRACE(args);
    const CliResult r = runDrover(args);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output, "") << "-q printed more than errors";
  }
}

// "without the flag the missing `000010.bin` is reported as an error"
TEST(ReadmePromises, InfoReportsAScanListedInTimesTxtButMissingAsAnError) {
  TempDir dir;
  const fs::path seq = kittiSequence(dir);
  fs::remove(seq / "velodyne" / "000005.bin");
  expectOneErrorNaming(runDrover("info " + seq.string() + " --format kitti"), "000005.bin");
  EXPECT_EQ(runDrover("info " + seq.string() + " --format kitti --max-frames 5").exit_code, 0);
}

// "`--force` replaces an existing folder only when it is empty or holds an earlier simulated dataset and nothing else"
TEST(ReadmePromises, SimRefusesAnExistingFolderWithoutForceAndReplacesADatasetWithIt) {
  TempDir dir;
  const std::string sim = "sim -q --scenario straight --duration 0.3 --no-camera --out " + (dir / "ds").string();
  ASSERT_EQ(runDrover(sim).exit_code, 0);
  writeText(dir / "ds" / "marker.txt", "x");
  expectOneErrorNaming(runDrover(sim), (dir / "ds").string());
  EXPECT_TRUE(fs::exists(dir / "ds" / "marker.txt")) << "a refused sim touched the folder";
  // With a file of the user's in it the folder is no longer only a dataset: even --force keeps it.
  expectOneErrorNaming(runDrover(sim + " --force"), (dir / "ds").string());
  EXPECT_TRUE(fs::exists(dir / "ds" / "marker.txt")) << "--force deleted a file that was not the dataset's";
  fs::remove(dir / "ds" / "marker.txt");
  EXPECT_EQ(runDrover(sim + " --force").exit_code, 0);
  EXPECT_TRUE(fs::exists(dir / "ds" / "scenario.json"));
}

// "`--force` replaces an existing folder" -- a folder, never anything that is not a dataset (issue 14, item 1).
TEST(ReadmePromises, SimForceRefusesToReplaceAFolderThatIsNotADataset) {
  TempDir dir;
  writeText(dir / "mine" / "thesis.tex", "years of work\n");
  writeText(dir / "file.txt", "a plain file\n");
  for (const fs::path& target : {dir / "mine", dir / "file.txt"}) {
    SCOPED_TRACE(target.string());
    expectOneErrorNaming(runDrover("sim -q --scenario straight --duration 0.3 --no-camera --force --out " + target.string()),
                   target.string());
  }
  EXPECT_TRUE(fs::exists(dir / "mine" / "thesis.tex"));
  EXPECT_TRUE(fs::exists(dir / "file.txt"));
}

// "The folder is written as `OUT.partial/` and renamed when complete, so an interrupted run never leaves a folder
// that looks like a dataset."
TEST(ReadmePromises, AKilledSimLeavesNoFolderThatLooksLikeADataset) {
  TempDir dir;
  const fs::path out = dir / "farm";
  const std::string cmd = "timeout -s KILL 2 " + std::string(DROVER_BINARY) + " sim -q --scenario farm --out " +
                          out.string() + " > /dev/null 2>&1";
  ASSERT_NE(std::system(cmd.c_str()), 0) << "the farm course should take longer than 2 s";
  EXPECT_FALSE(fs::exists(out)) << "a killed sim left " << out;
}

// "Bad data never stops a run: NaN/inf points are dropped ... each with a warning and a counter in `report.json`"
// (issue 14, item 9: today one NaN stops the whole command).
TEST(ReadmePromises, RunDropsNanAndInfPointsWithAWarningAndACounter) {
  TempDir dir;
  const fs::path seq = kittiSequence(dir);
  auto scan = hallScan(1.0, 64, 360);
  scan[100][0] = std::numeric_limits<float>::quiet_NaN();
  scan[200][2] = std::numeric_limits<float>::infinity();
  writeBin(seq / "velodyne" / "000002.bin", scan);
  const CliResult r = runDrover(runKittiSequence(seq, dir / "run"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(taggedLines(r.output, "[warning]").empty()) << "no warning for the dropped points:\n" << r.output;
  EXPECT_EQ(fileLineCount(dir / "run" / "trajectory.tum"), 6u);
  EXPECT_GE(readJson(dir / "run" / "report.json")["counts"]["points_dropped"].get<long>(), 2);
}

// "empty sweeps ... are skipped ... each with a warning"; and `trajectory_kitti.txt` has "one line per scan"
// (issue 14, item 2: a skipped sweep shifted every later line).
TEST(ReadmePromises, RunSkipsAnEmptySweepWithAWarningAndKeepsOneKittiLinePerScan) {
  TempDir dir;
  const fs::path seq = kittiSequence(dir);
  writeText(seq / "velodyne" / "000003.bin", "");
  const CliResult r = runDrover(runKittiSequence(seq, dir / "run"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(taggedLines(r.output, "[warning]").empty()) << r.output;
  EXPECT_EQ(readJson(dir / "run" / "report.json")["counts"]["scans_skipped_empty"], 1);
  EXPECT_EQ(fileLineCount(dir / "run" / "trajectory_kitti.txt"), 6u) << "one line per scan of times.txt";
}

// "A dataset without lidar sweeps is an error (exit 2)." -- and so is one where no sweep produced a pose
// (issue 14, item 5: every sweep skipped gave exit 0 and no trajectory).
TEST(ReadmePromises, RunWithoutAnyUsableSweepIsAnError) {
  TempDir dir;
  const fs::path seq = kittiSequence(dir);
  for (int i = 0; i < 6; ++i) writeText(seq / "velodyne" / ("00000" + std::to_string(i) + ".bin"), "");
  const CliResult r = runDrover(runKittiSequence(seq, dir / "run"));
  expectOneErrorNaming(r, seq.string());
  EXPECT_FALSE(fs::exists(dir / "run" / "report.json"));
}

// The simulated course shared by the IMU promises (2 s straight, no camera), with imu.csv rewritten by `edit`.
class SimImuPromise : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();
    sim_ = runDrover("sim -q --scenario straight --duration 3 --no-camera --out " + (*dir_ / "ds").string());
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override { ASSERT_EQ(sim_.exit_code, 0) << sim_.output; }
  // A copy of the course whose imu.csv rows pass through edit(t_ns, row) (return "" to delete the row).
  template <typename F>
  fs::path editedCopy(const std::string& name, F edit) {
    const fs::path copy = *dir_ / name;
    fs::remove_all(copy);
    fs::copy(*dir_ / "ds", copy, fs::copy_options::recursive);
    std::istringstream in(readText(*dir_ / "ds" / "imu.csv"));
    std::string out;
    for (std::string l; std::getline(in, l);) {
      if (l.empty() || l[0] == '#' || l[0] == 't') {
        out += l + "\n";
        continue;
      }
      const std::string e = edit(std::stoll(l.substr(0, l.find(','))), l);
      if (!e.empty()) out += e + "\n";
    }
    writeText(copy / "imu.csv", out);
    return copy;
  }
  CliResult run(const fs::path& ds) {
    return runDrover("run " + ds.string() + " --format sim --config " + config("farm_sim.yaml") + " --out " +
                     (ds.string() + "_run"));
  }
  static inline std::unique_ptr<TempDir> dir_;
  static inline CliResult sim_;
};

// "IMU gaps are bridged and counted ... each with a warning and a counter in `report.json`"
TEST_F(SimImuPromise, AnImuGapIsBridgedCountedAndWarned) {
  const fs::path ds = editedCopy("gap", [](long long t, const std::string& row) {
    return t > 2'000'000'000LL && t < 2'400'000'000LL ? std::string() : row;  // 0.4 s without IMU
  });
  const CliResult r = run(ds);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_GE(readJson(ds.string() + "_run/report.json")["counts"]["imu"]["gaps"].get<int>(), 1);
  bool warned = false;
  for (const auto& l : taggedLines(r.output, "[warning]")) warned = warned || contains(l, "gap");
  EXPECT_TRUE(warned) << "no warning names the IMU gap:\n" << r.output;
}

// "IMU spikes (|a| > 150 m/s², |ω| > 35 rad/s) dropped ... each with a warning and a counter in `report.json`"
TEST_F(SimImuPromise, AnImuSpikeIsDroppedCountedAndWarned) {
  const fs::path ds = editedCopy("spike", [](long long t, std::string row) {
    if (t < 2'000'000'000LL || t > 2'010'000'000LL) return row;
    std::vector<std::string> f;
    std::stringstream ss(row);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    f[4] = "1000";  // ax [m/s^2]
    std::string out;
    for (std::size_t i = 0; i < f.size(); ++i) out += (i ? "," : "") + f[i];
    return out;
  });
  const CliResult r = run(ds);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_GE(readJson(ds.string() + "_run/report.json")["counts"]["imu"]["dropped_spike"].get<int>(), 1);
  bool warned = false;
  for (const auto& l : taggedLines(r.output, "[warning]")) warned = warned || contains(l, "spike");
  EXPECT_TRUE(warned) << "no warning names the IMU spike:\n" << r.output;
}

// "sweeps whose stamp does not advance are skipped ... each with a warning" (issue 14, item 9: readers stop instead)
TEST_F(SimImuPromise, ASweepWhoseStampDoesNotAdvanceIsSkippedWithAWarning) {
  const fs::path ds = editedCopy("stamp", [](long long, const std::string& row) { return row; });
  std::istringstream in(readText(ds / "lidar" / "timestamps.csv"));
  std::vector<std::string> rows;
  for (std::string l; std::getline(in, l);) rows.push_back(l);
  ASSERT_GT(rows.size(), 12u);
  const auto field = [](const std::string& l, int i) {
    std::stringstream ss(l);
    std::string x;
    for (int k = 0; k <= i; ++k) std::getline(ss, x, ',');
    return x;
  };
  rows[11] = field(rows[11], 0) + "," + field(rows[10], 1) + "," + field(rows[10], 2);  // the previous scan's stamps
  std::string text;
  for (const auto& l : rows) text += l + "\n";
  writeText(ds / "lidar" / "timestamps.csv", text);
  const CliResult r = run(ds);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(taggedLines(r.output, "[warning]").empty()) << r.output;
  // The reader drops the repeated stamp (a measurement that does not advance on its own sensor), so the odometry
  // never sees it.
  EXPECT_EQ(readJson(ds.string() + "_run/report.json")["counts"]["measurements_dropped"], 1);
}

}  // namespace
}  // namespace drover::test
