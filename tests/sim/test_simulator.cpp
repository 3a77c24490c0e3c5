// The simulator: schedule (counts, order, offsets), calibration, ground truth and determinism, on a small
// hand-built scenario (a straight drive past a wall) so the test depends on no scenario catalogue.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <numbers>

#include "io/sim_dataset.hpp"
#include "io/text_parsing.hpp"
#include "sim/simulator.hpp"
#include "support/temp_dir.hpp"
#include "small_scenario.hpp"

namespace drover::sim {
namespace {
namespace fs = std::filesystem;
using fixture::runAll;
using fixture::sameMeasurement;
using fixture::smallConfig;
using fixture::smallScenario;

TEST(SimulatorConfig, DefaultsMountTheSensorsOnTheRobot) {
  const SimulatorConfig c = SimulatorConfig::defaults();
  EXPECT_EQ(c.validate(), "");
  EXPECT_TRUE(c.T_imu_lidar.translation().isApprox(Eigen::Vector3d(0.05, 0, 0.30)));
  EXPECT_TRUE(c.T_imu_lidar.linear().isIdentity());
  EXPECT_TRUE(c.T_imu_cam.translation().isApprox(Eigen::Vector3d(0.20, 0, 0.10)));
  const Eigen::Matrix3d R = c.T_imu_cam.linear();
  // Camera z looks along body x, camera x along -body y, camera y along -body z, each within ~1 deg.
  const double tol = std::cos(1.5 * std::numbers::pi / 180.0);
  EXPECT_GT(R.col(2).dot(Eigen::Vector3d::UnitX()), tol);
  EXPECT_GT(R.col(0).dot(-Eigen::Vector3d::UnitY()), tol);
  EXPECT_GT(R.col(1).dot(-Eigen::Vector3d::UnitZ()), tol);
  Eigen::Matrix3d nominal;
  nominal << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const double misalignment_deg = Eigen::AngleAxisd(nominal.transpose() * R).angle() * 180.0 / std::numbers::pi;
  EXPECT_NEAR(misalignment_deg, 1.0, 1e-9);
  EXPECT_EQ(c.camera_time_offset, 5'000'000);
  EXPECT_EQ(c.lidar_time_offset, 0);
  EXPECT_EQ(c.camera.intrinsics.width, 640);
}

TEST(SimulatorConfig, ValidateNamesTheBadValue) {
  SimulatorConfig c = SimulatorConfig::defaults();
  c.ground_truth_rate_hz = 50;
  EXPECT_NE(c.validate().find("ground_truth_rate_hz"), std::string::npos);
  const Scenario s = smallScenario();
  EXPECT_THROW(Simulator(s, c, 1), std::invalid_argument);
  c = SimulatorConfig::defaults();
  c.T_imu_cam.linear() *= 2.0;
  EXPECT_NE(c.validate().find("T_imu_cam"), std::string::npos);
}

TEST(Simulator, CountsMatchRatesTimesDuration) {
  const Scenario s = smallScenario();
  const Simulator sim(s, smallConfig(), 7);
  std::size_t imu = 0, lidar = 0, camera = 0;
  for (const Measurement& m : runAll(sim)) (m.index() == 0 ? imu : m.index() == 1 ? lidar : camera)++;
  EXPECT_EQ(imu, 401u);    // 200 Hz over [0, 2] s, both ends
  EXPECT_EQ(lidar, 20u);   // sweeps starting at 0, 0.1, ..., 1.9 s end by 2 s
  EXPECT_EQ(camera, 30u);  // exposures centred at 5 ms + k / 15 s ending by 2 s: k = 0..29
  const Simulator::Counts expected = sim.expectedCounts();
  EXPECT_EQ(expected.imu, imu);
  EXPECT_EQ(expected.lidar, lidar);
  EXPECT_EQ(expected.camera, camera);
}

TEST(Simulator, EmitsMeasurementsInStampOrderWithTiesImuLidarCamera) {
  const Scenario s = smallScenario();
  SimulatorConfig c = smallConfig();
  c.camera_time_offset = -5'000'000;  // camera stamps at 10 ms + k / 10 s: each ties an IMU sample, no sweep
  c.camera.rate_hz = 10;
  c.lidar_time_offset = 0;            // sweeps at k / 10 s tie IMU samples
  const std::vector<Measurement> all = runAll(Simulator(s, c, 3));
  std::array<Time, 3> last = {-1, -1, -1};
  std::size_t ties = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Time t = measurementTime(all[i]);
    EXPECT_GT(t, last[all[i].index()]) << "each stream strictly increasing, measurement " << i;
    last[all[i].index()] = t;
    if (i == 0) continue;
    const Time prev = measurementTime(all[i - 1]);
    ASSERT_LE(prev, t) << "measurement " << i;
    if (prev == t) {
      ++ties;
      EXPECT_LT(all[i - 1].index(), all[i].index()) << "tie order IMU, lidar, camera at " << t;
    }
  }
  EXPECT_EQ(ties, 20u + 20u);  // every sweep and every frame starts on an IMU stamp
}

TEST(Simulator, StampsAreTrueTimeMinusTheOffsets) {
  const Scenario s = smallScenario();
  SimulatorConfig c = smallConfig();
  c.lidar_time_offset = 2'000'000;
  std::vector<Time> sweeps, frames;
  for (const Measurement& m : runAll(Simulator(s, c, 3))) {
    if (const auto* scan = std::get_if<LidarScan>(&m)) {
      sweeps.push_back(scan->t);
      EXPECT_TRUE(scan->has_time && scan->has_ring);
      EXPECT_GT(scan->t_end, scan->t);
      EXPECT_LE(scan->t_end - scan->t, 100'000'000);
    }
    if (const auto* f = std::get_if<CameraFrame>(&m)) frames.push_back(f->t);
  }
  ASSERT_EQ(sweeps.size(), 20u);
  ASSERT_EQ(frames.size(), 30u);
  for (std::size_t k = 0; k < sweeps.size(); ++k)
    EXPECT_EQ(sweeps[k], static_cast<Time>(k) * 100'000'000 - 2'000'000);
  for (std::size_t k = 0; k < frames.size(); ++k)
    EXPECT_EQ(frames[k], 5'000'000 + std::llround(static_cast<double>(k) * 1e9 / 15.0) - 5'000'000);
}

TEST(Simulator, CalibrationEqualsTheConfig) {
  const Scenario s = smallScenario();
  const SimulatorConfig c = smallConfig();
  const Calibration cal = Simulator(s, c, 1).calibration();
  EXPECT_TRUE(cal.T_imu_lidar.isApprox(c.T_imu_lidar, 0));
  EXPECT_TRUE(cal.T_imu_cam.isApprox(c.T_imu_cam, 0));
  EXPECT_EQ(cal.camera.width, 64);
  EXPECT_EQ(cal.camera.fx, 46.0);
  EXPECT_EQ(cal.camera.distortion_coeffs, c.camera.intrinsics.distortion_coeffs);
  EXPECT_EQ(cal.camera_time_offset, c.camera_time_offset);
  EXPECT_EQ(cal.lidar_time_offset, c.lidar_time_offset);
  const io::SimDatasetDescription d = Simulator(s, c, 1).datasetDescription();
  EXPECT_EQ(d.sensors.lidar_rings, 16);
  EXPECT_EQ(d.sensors.lidar_columns, 360);
  EXPECT_EQ(d.scenario.segments.at(0).condition, "straight");
  EXPECT_NEAR(d.scenario.path_length_m, 2.0, 1e-6);
}

TEST(Simulator, GroundTruthIsTheImuPoseAt200Hz) {
  const Scenario s = smallScenario();
  const Trajectory gt = Simulator(s, smallConfig(), 1).groundTruth();
  ASSERT_EQ(gt.size(), 401u);
  for (std::size_t i = 0; i < gt.size(); ++i) {
    EXPECT_EQ(gt[i].t, static_cast<Time>(i) * 5'000'000);
    EXPECT_TRUE(gt[i].T_world_body.isApprox(s.trajectory->pose(gt[i].t), 1e-12));
  }
  EXPECT_NEAR(gt.back().T_world_body.translation().x(), 2.0, 1e-9);
}

TEST(Simulator, SameSeedAndAnyChunkSizeGiveTheSameMeasurements) {
  const Scenario s = smallScenario();
  const std::vector<Measurement> a = runAll(Simulator(s, smallConfig(), 11));
  const std::vector<Measurement> b = runAll(Simulator(s, smallConfig(), 11), 300'000'000);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(sameMeasurement(a[i], b[i])) << "measurement " << i;
  const std::vector<Measurement> c = runAll(Simulator(s, smallConfig(), 12));
  ASSERT_EQ(a.size(), c.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differ += sameMeasurement(a[i], c[i]) ? 0 : 1;
  EXPECT_GT(differ, a.size() / 2) << "another seed gives other noise";
}

TEST(Simulator, OutputDoesNotDependOnTheThreadCount) {
  const Scenario s = smallScenario();
  const std::vector<Measurement> parallel = runAll(Simulator(s, smallConfig(), 4));
  std::vector<Measurement> serial;
  {
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    serial = runAll(Simulator(s, smallConfig(), 4));
  }
  ASSERT_EQ(parallel.size(), serial.size());
  for (std::size_t i = 0; i < serial.size(); ++i)
    ASSERT_TRUE(sameMeasurement(parallel[i], serial[i])) << "measurement " << i;
}

// ---- through the dataset writer ---------------------------------------------------------------------------------

void writeDataset(const Scenario& s, std::uint64_t seed, const fs::path& dir) {
  const Simulator sim(s, smallConfig(), seed);
  io::SimDatasetWriter writer(dir.string(), sim.datasetDescription());
  sim.run([&](Measurement&& m) { writer.add(std::move(m)); });
  writer.finish(sim.groundTruth());
}

// Relative path -> bytes of every file under dir.
std::map<std::string, std::string> folderBytes(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = io::readTextFile(e.path().string());
  return files;
}

TEST(Simulator, SameSeedWritesByteIdenticalFoldersAndAnotherSeedDoesNot) {
  const Scenario s = smallScenario();
  test::TempDir tmp;
  writeDataset(s, 5, tmp / "a");
  writeDataset(s, 5, tmp / "b");
  writeDataset(s, 6, tmp / "c");
  const auto a = folderBytes(tmp / "a"), b = folderBytes(tmp / "b"), c = folderBytes(tmp / "c");
  EXPECT_EQ(a.size(), 6u + 20u + 30u);  // calibration, scenario, imu, groundtruth, 2 timestamps + payloads
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, bytes] : a) EXPECT_TRUE(b.at(name) == bytes) << name << " differs between equal seeds";
  EXPECT_NE(a.at("imu.csv"), c.at("imu.csv"));
  EXPECT_NE(a.at("lidar/000003.bin"), c.at("lidar/000003.bin"));
  EXPECT_NE(a.at("camera/000003.png"), c.at("camera/000003.png"));
  EXPECT_EQ(a.at("groundtruth.txt"), c.at("groundtruth.txt"));  // same scenario, same path
}

}  // namespace
}  // namespace drover::sim
