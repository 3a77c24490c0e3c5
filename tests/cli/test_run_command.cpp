// `drover run` end to end: the run folder's files on the real KITTI snippet and on a tiny simulated course, and
// bad input (missing dataset, unknown format, bad config key, no lidar, corrupt scan) -> exit 2 with one clear line.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/cloud_io.hpp"
#include "io/trajectory_io.hpp"
#include "support/cli.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;
using Json = nlohmann::json;

std::string config(const std::string& name) { return std::string(DROVER_SOURCE_DIR) + "/config/" + name; }

std::size_t lines(const fs::path& p) {
  std::ifstream in(p);
  std::size_t n = 0;
  for (std::string l; std::getline(in, l);) n += !l.empty() && l[0] != '#';
  return n;
}

TEST(RunCli, KittiSnippetWritesEveryRunFileAndPrintsTheApeTable) {
  const fs::path seq = sharedData("kitti/sequences/00");
  DROVER_REQUIRE_SHARED(seq / "velodyne" / "000009.bin");
  TempDir dir;
  const fs::path out = dir / "run";
  const CliResult r = runDrover("run " + seq.string() + " --format kitti --config " + config("kitti.yaml") +
                                " --max-frames 10 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "rmse")) << r.output;
  EXPECT_EQ(lines(out / "trajectory.tum"), 10u);
  const Trajectory kitti = io::readKitti((out / "trajectory_kitti.txt").string());
  ASSERT_EQ(kitti.size(), 10u);
  EXPECT_TRUE(kitti.front().T_world_body.isApprox(Eigen::Isometry3d::Identity(), 1e-9));
  // Camera-0 frame: the car drives along +z of camera 0.
  EXPECT_GT(kitti.back().T_world_body.translation().z(), 5.0);
  EXPECT_GE(lines(out / "keyframes.tum"), 2u);
  EXPECT_GT(io::readPcdBinary((out / "map.pcd").string()).size(), 1000u);
  EXPECT_TRUE(fs::exists(out / "map.ply"));
  const Json report = readJson(out / "report.json");
  EXPECT_EQ(report["counts"]["scans_processed"], 10);
  EXPECT_EQ(report["mode"], "lidar");
  EXPECT_EQ(report["body_frame"], "lidar");
  EXPECT_GT(report["timings"]["total"]["mean_ms"].get<double>(), 0.0);
  EXPECT_TRUE(std::isfinite(report["ape"]["rmse"].get<double>()));
  EXPECT_EQ(report["scans"].size(), 10u);
}

TEST(RunCli, SimulatedCourseRunsWithAndWithoutTheImuInTheImuFrame) {
  TempDir dir;
  const fs::path data = dir / "straight";
  ASSERT_EQ(runDrover("sim --scenario straight --duration 4 --no-camera -q --out " + data.string()).exit_code, 0);
  for (const bool imu : {true, false}) {
    const fs::path out = dir / (imu ? "imu" : "lidar");
    const CliResult r = runDrover("run " + data.string() + " --format sim --config " + config("farm_sim.yaml") +
                                  " --out " + out.string() + (imu ? "" : " --no-imu"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const Json report = readJson(out / "report.json");
    EXPECT_EQ(report["mode"], imu ? "lidar+imu" : "lidar");
    EXPECT_EQ(report["body_frame"], "imu");
    EXPECT_EQ(report["counts"]["imu_initialized"], imu);
    EXPECT_NEAR(static_cast<double>(lines(out / "trajectory.tum")), 39.0, 1.0);
    EXPECT_EQ(report["counts"]["smoother_resets"], 0);
    // A straight path: no SE(3) alignment is possible, and the report says so instead of failing the run.
    EXPECT_TRUE(report["ape"].contains("error")) << report["ape"].dump();
  }
}

TEST(RunCli, MissingDatasetExitsWithCode2) {
  TempDir dir;
  const CliResult r = runDrover("run /nonexistent/seq --format kitti --out " + (dir / "o").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "/nonexistent/seq")) << r.output;
}

TEST(RunCli, UnknownFormatExitsWithCode2) {
  TempDir dir;
  const CliResult r = runDrover("run " + dir.path().string() + " --format velodyne --out " + (dir / "o").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST(RunCli, UnknownOdometryKeyInTheConfigIsNamedWithItsLine) {
  const fs::path seq = sharedData("kitti/sequences/00");
  DROVER_REQUIRE_SHARED(seq / "velodyne" / "000009.bin");
  TempDir dir;
  const fs::path yaml = dir / "bad.yaml";
  std::ofstream(yaml) << "odometry:\n  use_imu: false\n  matcher:\n    max_iteratons: 5\n";
  const CliResult r = runDrover("run " + seq.string() + " --format kitti --max-frames 10 --config " + yaml.string() +
                                " --out " + (dir / "o").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "odometry.matcher.max_iteratons")) << r.output;
  EXPECT_TRUE(contains(r.output, "line 4")) << r.output;
}

TEST(RunCli, DatasetWithoutLidarIsAnError) {
  const fs::path euroc = sharedData("euroc/V1_01_easy_micro");
  DROVER_REQUIRE_SHARED(euroc);
  TempDir dir;
  const CliResult r = runDrover("run " + euroc.string() + " --format euroc --config " + config("euroc.yaml") +
                                " --duration 2 --out " + (dir / "o").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "no lidar")) << r.output;
}

TEST(RunCli, CorruptScanFileIsNamedAndExitsWithCode2) {
  const fs::path seq = sharedData("kitti/sequences/00");
  DROVER_REQUIRE_SHARED(seq / "velodyne" / "000002.bin");
  TempDir dir;
  const fs::path copy = dir / "00";
  fs::create_directories(copy / "velodyne");
  for (const char* f : {"calib.txt", "times.txt", "poses.txt"}) fs::copy_file(seq / f, copy / f);
  for (const char* f : {"000000.bin", "000001.bin", "000002.bin"})
    fs::copy_file(seq / "velodyne" / f, copy / "velodyne" / f);
  fs::resize_file(copy / "velodyne" / "000001.bin", fs::file_size(copy / "velodyne" / "000001.bin") - 5);
  const fs::path yaml = dir / "k.yaml";
  std::ofstream(yaml) << "dataset:\n  load_images: false\nodometry:\n  use_imu: false\n";
  const CliResult r = runDrover("run " + copy.string() + " --format kitti --max-frames 3 --config " + yaml.string() +
                                " --out " + (dir / "o").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "000001.bin")) << r.output;
}

}  // namespace
}  // namespace drover::test
