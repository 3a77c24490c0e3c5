// `drover run` on data that is partly or wholly unusable: a skipped sweep keeps trajectory_kitti.txt at one line per
// scan, a run in which no sweep produced a pose fails with its reason, and the IMU's problems are said where the
// user looks (the "fusing:" line, one warning per gap or spike) instead of only in report.json.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <limits>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/trajectory_io.hpp"
#include "support/cli.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;
using Json = nlohmann::json;

std::vector<std::string> linesWith(const std::string& output, const std::string& part) {
  std::vector<std::string> out;
  for (const std::string& l : linesOf(output))
    if (contains(l, part)) out.push_back(l);
  return out;
}

// The first `frames` frames of the shared KITTI 00 snippet, copied so that scans can be damaged.
fs::path copyKitti(const TempDir& dir, int frames) {
  const fs::path seq = sharedData("kitti/sequences/00");
  const fs::path copy = dir / "00";
  fs::create_directories(copy / "velodyne");
  for (const char* f : {"calib.txt", "times.txt", "poses.txt"}) fs::copy_file(seq / f, copy / f);
  for (int i = 0; i < frames; ++i) {
    const std::string name = fmt::format("{:06d}.bin", i);
    fs::copy_file(seq / "velodyne" / name, copy / "velodyne" / name);
  }
  return copy;
}

std::string runKitti(const fs::path& seq, int frames, const fs::path& out) {
  return "run " + seq.string() + " --format kitti --config " + config("kitti.yaml") + " --max-frames " +
         std::to_string(frames) + " --no-loop --out " + out.string();
}

// ------------------------------------------------------------------------------------------ KITTI: a skipped scan

TEST(RunBadData, AnEmptyKittiScanStillGetsItsLineInTrajectoryKittiInterpolatedBetweenItsNeighbours) {
  DROVER_REQUIRE_SHARED(sharedData("kitti/sequences/00/velodyne/000005.bin"));
  TempDir dir;
  const fs::path seq = copyKitti(dir, 6);
  std::ofstream(seq / "velodyne" / "000003.bin", std::ios::trunc).close();  // scan 3: no points
  const CliResult r = runDrover(runKitti(seq, 6, dir / "o"));
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const Trajectory kitti = io::readKitti((dir / "o" / "trajectory_kitti.txt").string());
  ASSERT_EQ(kitti.size(), 6u) << "one line per scan, the skipped one included";
  EXPECT_EQ(io::readTum((dir / "o" / "trajectory.tum").string()).size(), 5u) << "trajectory.tum: estimated only";
  // The car drives at about 1 m per scan: line 3 lies between lines 2 and 4, near their midpoint.
  const Eigen::Vector3d p2 = kitti[2].T_world_body.translation(), p3 = kitti[3].T_world_body.translation(),
                        p4 = kitti[4].T_world_body.translation();
  EXPECT_GT((p4 - p2).norm(), 0.5);
  EXPECT_LT((p3 - 0.5 * (p2 + p4)).norm(), 0.02 * (p4 - p2).norm());

  const Json filled = readJson(dir / "o" / "report.json")["trajectory_kitti"];
  EXPECT_EQ(filled["lines"], 6);
  ASSERT_EQ(filled["filled"].size(), 1u) << filled.dump();
  EXPECT_EQ(filled["filled"][0]["line"], 3);
  EXPECT_EQ(filled["filled"][0]["pose"], "interpolated");
  EXPECT_EQ(linesWith(r.output, "trajectory_kitti.txt: 1 of 6 scans had no pose").size(), 1u) << r.output;
}

TEST(RunBadData, AnEmptyLastKittiScanIsExtrapolatedSoTheFileStillHasOneLinePerScan) {
  DROVER_REQUIRE_SHARED(sharedData("kitti/sequences/00/velodyne/000004.bin"));
  TempDir dir;
  const fs::path seq = copyKitti(dir, 5);
  std::ofstream(seq / "velodyne" / "000004.bin", std::ios::trunc).close();
  const CliResult r = runDrover(runKitti(seq, 5, dir / "o"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Trajectory kitti = io::readKitti((dir / "o" / "trajectory_kitti.txt").string());
  ASSERT_EQ(kitti.size(), 5u);
  // Constant velocity: the step 3 -> 4 repeats the step 2 -> 3 (to a few centimetres: the car barely accelerates).
  const Eigen::Vector3d step23 = kitti[3].T_world_body.translation() - kitti[2].T_world_body.translation();
  const Eigen::Vector3d step34 = kitti[4].T_world_body.translation() - kitti[3].T_world_body.translation();
  EXPECT_LT((step34 - step23).norm(), 0.05) << step23.transpose() << " vs " << step34.transpose();
  EXPECT_EQ(readJson(dir / "o" / "report.json")["trajectory_kitti"]["filled"][0]["pose"], "extrapolated");
}

// ------------------------------------------------------------------------------- no sweep produced a pose at all

TEST(RunBadData, ARunWhoseSweepsAreAllEmptyExitsWith2SayingNoSweepProducedAPoseAndWritesNoFolder) {
  DROVER_REQUIRE_SHARED(sharedData("kitti/sequences/00/velodyne/000002.bin"));
  TempDir dir;
  const fs::path seq = copyKitti(dir, 3);
  for (int i = 0; i < 3; ++i) std::ofstream(seq / "velodyne" / fmt::format("{:06d}.bin", i), std::ios::trunc).close();
  const CliResult r = runDrover(runKitti(seq, 3, dir / "o"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  const std::vector<std::string> errors = linesWith(r.output, "[error]");
  ASSERT_EQ(errors.size(), 1u) << r.output;
  EXPECT_TRUE(contains(errors[0], seq.string())) << errors[0];
  EXPECT_TRUE(contains(errors[0], "no sweep produced a pose")) << errors[0];
  EXPECT_TRUE(contains(errors[0], "of 3 sweeps, 3 had too few valid points")) << errors[0];
  EXPECT_FALSE(fs::exists(dir / "o"));
}

TEST(RunBadData, ARunWhoseSweepsAreAllNonFiniteExitsWith2CountingTheDroppedPoints) {
  DROVER_REQUIRE_SHARED(sharedData("kitti/sequences/00/velodyne/000001.bin"));
  TempDir dir;
  const fs::path seq = copyKitti(dir, 2);
  const std::vector<float> nan_points(4 * 500, std::numeric_limits<float>::quiet_NaN());
  for (int i = 0; i < 2; ++i)
    std::ofstream(seq / "velodyne" / fmt::format("{:06d}.bin", i), std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(nan_points.data()), static_cast<std::streamsize>(nan_points.size() * 4));
  const CliResult r = runDrover(runKitti(seq, 2, dir / "o"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  const std::vector<std::string> errors = linesWith(r.output, "[error]");
  ASSERT_EQ(errors.size(), 1u) << r.output;
  EXPECT_TRUE(contains(errors[0], "no sweep produced a pose")) << errors[0];
  EXPECT_FALSE(fs::exists(dir / "o"));
}

// ------------------------------------------------------------------------------- IMU problems are said, not hidden

// An imu.csv row (t_ns,wx,wy,wz,ax,ay,az) with field `index` replaced, and its newline.
std::string withField(const std::string& row, std::size_t index, const std::string& value) {
  std::vector<std::string> f;
  std::stringstream ss(row);
  for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
  f.at(index) = value;
  std::string out;
  for (const std::string& x : f) out += (out.empty() ? "" : ",") + x;
  return out + "\n";
}

// A 4 s simulated straight course (IMU at 200 Hz), made once; each test damages a copy of its imu.csv.
class RunImuProblems : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();
    sim_ = runDrover("sim -q --scenario straight --duration 4 --no-camera --out " + (*dir_ / "straight").string());
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override { ASSERT_EQ(sim_.exit_code, 0) << sim_.output; }

  // A copy of the course whose imu.csv is the header plus the rows `keep` accepts (row index, row text).
  static fs::path damagedCopy(const std::string& name,
                              const std::function<std::string(std::size_t, const std::string&)>& edit) {
    const fs::path copy = *dir_ / name;
    fs::copy(*dir_ / "straight", copy, fs::copy_options::recursive);
    std::ifstream in(*dir_ / "straight" / "imu.csv");
    std::string text, line;
    std::getline(in, line);
    text = line + "\n";
    for (std::size_t i = 0; std::getline(in, line); ++i) text += edit(i, line);
    writeText(copy / "imu.csv", text);
    return copy;
  }
  static CliResult run(const fs::path& data, const std::string& out) {
    return runDrover("run " + data.string() + " --format sim --config " + config("farm_sim.yaml") + " --no-loop --out " +
                     (*dir_ / out).string());
  }

  static inline std::unique_ptr<TempDir> dir_;
  static inline CliResult sim_;
};

TEST_F(RunImuProblems, AnEmptyImuFileIsAWarningThatTheRunFusesLidarOnlyAndTheReportSaysLidar) {
  const fs::path data = damagedCopy("no_imu", [](std::size_t, const std::string&) { return std::string(); });
  const CliResult r = run(data, "o_no_imu");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(contains(r.output, "lidar + IMU")) << r.output;
  const std::vector<std::string> fusing = linesWith(r.output, "fusing: lidar only");
  ASSERT_EQ(fusing.size(), 1u) << r.output;
  EXPECT_TRUE(contains(fusing[0], "[warning]") && contains(fusing[0], "no IMU sample")) << fusing[0];
  const Json report = readJson(*dir_ / "o_no_imu" / "report.json");
  EXPECT_EQ(report["mode"], "lidar");
  EXPECT_EQ(report["imu_requested"], true);
}

TEST_F(RunImuProblems, AHealthyImuIsAnnouncedAsFusedWithHowItWasInitialised) {
  const CliResult r = run(*dir_ / "straight", "o_ok");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<std::string> fusing = linesWith(r.output, "fusing: lidar + IMU");
  ASSERT_EQ(fusing.size(), 1u) << r.output;
  EXPECT_TRUE(contains(fusing[0], "[info]") && contains(fusing[0], "static start")) << fusing[0];
  EXPECT_TRUE(linesWith(r.output, "IMU gap").empty() && linesWith(r.output, "spike").empty()) << r.output;
}

TEST_F(RunImuProblems, EachImuSpikeAndGapGivesAWarningWithItsTime) {
  // Rows 400-459 (0.3 s at 200 Hz, after the 1 s initialisation) removed; row 600 an accelerometer spike.
  const fs::path data = damagedCopy("spiky", [](std::size_t i, const std::string& row) -> std::string {
    if (i >= 400 && i < 460) return "";
    return i == 600 ? withField(row, 4, "400.0") : row + "\n";  // ax [m/s^2], far beyond the 150 m/s^2 limit
  });
  const CliResult r = run(data, "o_spiky");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<std::string> gaps = linesWith(r.output, "IMU gap of 0.30");
  ASSERT_EQ(gaps.size(), 1u) << r.output;
  EXPECT_TRUE(contains(gaps[0], "[warning]")) << gaps[0];
  const std::vector<std::string> spikes = linesWith(r.output, "dropped: spike (|a| = 400");
  ASSERT_EQ(spikes.size(), 1u) << r.output;
  const Json imu = readJson(*dir_ / "o_spiky" / "report.json")["counts"]["imu"];
  EXPECT_EQ(imu["gaps"], 1);
  EXPECT_EQ(imu["dropped_spike"], 1);
}

TEST_F(RunImuProblems, AFloodOfImuProblemsIsShownAFewTimesThenOnlyCounted) {
  // Every 10th row a spike from 1.5 s on: about 50 spikes, five lines and one "not shown" line.
  const fs::path data = damagedCopy("flood", [](std::size_t i, const std::string& row) -> std::string {
    return i >= 300 && i % 10 == 0 ? withField(row, 4, "999") : row + "\n";
  });
  const CliResult r = run(data, "o_flood");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(linesWith(r.output, "dropped: spike").size(), 5u) << r.output;
  EXPECT_EQ(linesWith(r.output, "further IMU problems of this kind (dropped_spike) are not shown").size(), 1u);
  EXPECT_GT(readJson(*dir_ / "o_flood" / "report.json")["counts"]["imu"]["dropped_spike"].get<int>(), 40);
}

}  // namespace
}  // namespace drover::test
