// `drover sim --format bag`'s writer (io/sim_bag.hpp) holds what the simulated folder holds: one simulation written
// both ways and read back by the sim reader and by the bag reader (with config/farm_sim_bag.yaml's topics) gives the
// same IMU samples, sweeps, images and ground truth, the bag's stamps shifted by kSimBagEpoch. And
// config/farm_sim_bag.yaml describes the simulated robot: its calibration is the simulator's, its other sections are
// config/farm_sim.yaml's.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <memory>
#include <string>
#include <vector>

#include "io/bag_reader.hpp"
#include "io/config.hpp"
#include "io/sim_bag.hpp"
#include "io/sim_dataset.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;

std::string config(const std::string& name) { return std::string(DROVER_SOURCE_DIR) + "/config/" + name; }

struct Streams {
  std::vector<ImuSample> imu;
  std::vector<LidarScan> scans;
  std::vector<CameraFrame> frames;
};

Streams readStreams(Reader& reader) {
  Streams s;
  while (auto m = reader.next()) {
    if (auto* x = std::get_if<ImuSample>(&*m)) s.imu.push_back(*x);
    if (auto* x = std::get_if<LidarScan>(&*m)) s.scans.push_back(std::move(*x));
    if (auto* x = std::get_if<CameraFrame>(&*m)) s.frames.push_back(std::move(*x));
  }
  return s;
}

// One second of the straight course with every sensor, written as a folder and as a bag from the same run.
class SimBag : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    sim::ScenarioOptions so;
    so.seed = 4;
    so.duration_s = 1.0;
    const sim::Scenario scenario = sim::makeScenario("straight", so);
    const sim::Simulator simulator(scenario, sim::SimulatorConfig::defaults(), so.seed);
    SimDatasetWriter folder((*dir_ / "course").string(), simulator.datasetDescription());
    SimBagWriter bag((*dir_ / "course.bag").string(), simulator.datasetDescription(), simulator.groundTruthStates(),
                     false);
    simulator.run([&](Measurement&& m) {
      folder.add(Measurement(m));
      bag.add(std::move(m));
    });
    folder.finish(simulator.groundTruth());
    bag.finish();
    calibration_ = simulator.calibration();
    const std::unique_ptr<Reader> sim_reader = openSimDataset((*dir_ / "course").string(), DatasetOptions{});
    BagReader bag_reader((*dir_ / "course.bag").string(), loadDatasetOptions(config("farm_sim_bag.yaml")));
    folder_ = readStreams(*sim_reader);
    bag_ = readStreams(bag_reader);
    folder_gt_ = sim_reader->groundTruth();
    bag_gt_ = bag_reader.groundTruth();
    bag_warnings_ = bag_reader.warnings();
  }
  static void TearDownTestSuite() { dir_.reset(); }

  static inline std::unique_ptr<test::TempDir> dir_;
  static inline Streams folder_, bag_;
  static inline GroundTruth folder_gt_, bag_gt_;
  static inline std::vector<std::string> bag_warnings_;
  static inline Calibration calibration_;
};

TEST_F(SimBag, TheBagHasEveryTopicOfThePlatformConfigAndNoWarning) {
  EXPECT_TRUE(bag_warnings_.empty()) << bag_warnings_.front();
  EXPECT_GE(bag_.imu.size(), 201u);  // 200 Hz over about 1 s
  EXPECT_GE(bag_.scans.size(), 9u);
  EXPECT_GE(bag_.frames.size(), 14u);
}

TEST_F(SimBag, ImuSamplesAreTheFoldersShiftedByTheEpoch) {
  ASSERT_EQ(bag_.imu.size(), folder_.imu.size());
  for (std::size_t k = 0; k < bag_.imu.size(); ++k) {
    const ImuSample &b = bag_.imu[k], &f = folder_.imu[k];
    EXPECT_EQ(b.t, f.t + kSimBagEpoch);
    EXPECT_EQ(b.omega_imu, f.omega_imu) << "sample " << k;
    EXPECT_EQ(b.acc_imu, f.acc_imu) << "sample " << k;
    ASSERT_EQ(b.q_world_imu.has_value(), f.q_world_imu.has_value());
    if (b.q_world_imu) {
      EXPECT_TRUE(b.q_world_imu->isApprox(*f.q_world_imu, 1e-12)) << "sample " << k;
    }
  }
}

TEST_F(SimBag, SweepsAreTheFoldersPointForPointWithTheSameTimes) {
  ASSERT_EQ(bag_.scans.size(), folder_.scans.size());
  for (std::size_t k = 0; k < bag_.scans.size(); ++k) {
    const LidarScan &b = bag_.scans[k], &f = folder_.scans[k];
    EXPECT_EQ(b.t, f.t + kSimBagEpoch);
    // The bag's sweep ends at its last point, the folder's at its last firing: at most a column (56 us) apart.
    EXPECT_LE(b.t_end, f.t_end + kSimBagEpoch);
    EXPECT_GE(b.t_end, f.t_end + kSimBagEpoch - 60'000);
    EXPECT_TRUE(b.has_time && b.has_ring);
    ASSERT_EQ(b.points.size(), f.points.size());
    for (std::size_t i = 0; i < b.points.size(); ++i) {
      const LidarPoint &p = b.points[i], &q = f.points[i];
      ASSERT_EQ(std::tie(p.x, p.y, p.z, p.intensity, p.ring), std::tie(q.x, q.y, q.z, q.intensity, q.ring))
          << "sweep " << k << " point " << i;
      ASSERT_NEAR(p.time_offset, q.time_offset, 1e-9) << "sweep " << k << " point " << i;
    }
  }
}

TEST_F(SimBag, ImagesAreTheFoldersByteForByte) {
  ASSERT_EQ(bag_.frames.size(), folder_.frames.size());
  for (std::size_t k = 0; k < bag_.frames.size(); ++k) {
    EXPECT_EQ(bag_.frames[k].t, folder_.frames[k].t + kSimBagEpoch);
    EXPECT_EQ(bag_.frames[k].image.channels, 1);
    EXPECT_TRUE(bag_.frames[k].image.data == folder_.frames[k].image.data) << "frame " << k;
  }
}

TEST_F(SimBag, TheGroundTruthTopicIsTheFoldersGroundTruthOfTheImu) {
  EXPECT_EQ(bag_gt_.body_frame, "imu");
  ASSERT_EQ(bag_gt_.poses.size(), folder_gt_.poses.size());
  for (std::size_t k = 0; k < bag_gt_.poses.size(); ++k) {
    EXPECT_EQ(bag_gt_.poses[k].t, folder_gt_.poses[k].t + kSimBagEpoch);
    EXPECT_TRUE(bag_gt_.poses[k].T_world_body.isApprox(folder_gt_.poses[k].T_world_body, 1e-12)) << "pose " << k;
  }
}

TEST(SimBagConfig, TheCalibrationOfFarmSimBagIsTheSimulatedRobots) {
  sim::SimulatorConfig c = sim::SimulatorConfig::defaults();
  const SimConfigSettings s = loadSimConfigSettings(config("farm_sim_bag.yaml"));
  if (s.lidar_time_offset_s) c.lidar_time_offset = fromSeconds(*s.lidar_time_offset_s);
  if (s.camera_time_offset_s) c.camera_time_offset = fromSeconds(*s.camera_time_offset_s);
  Calibration want;
  want.T_imu_lidar = c.T_imu_lidar;
  want.T_imu_cam = c.T_imu_cam;
  want.camera = c.camera.intrinsics;
  want.lidar_time_offset = c.lidar_time_offset;
  want.camera_time_offset = c.camera_time_offset;
  const Calibration got = loadDatasetOptions(config("farm_sim_bag.yaml")).calibration;
  EXPECT_TRUE(got.T_imu_lidar.isApprox(want.T_imu_lidar, 1e-12));
  EXPECT_TRUE(got.T_imu_cam.isApprox(want.T_imu_cam, 1e-12));
  EXPECT_EQ(got.lidar_time_offset, want.lidar_time_offset);
  EXPECT_EQ(got.camera_time_offset, want.camera_time_offset);
  EXPECT_EQ(got.camera.width, want.camera.width);
  EXPECT_EQ(got.camera.height, want.camera.height);
  EXPECT_EQ(got.camera.fx, want.camera.fx);
  EXPECT_EQ(got.camera.fy, want.camera.fy);
  EXPECT_EQ(got.camera.cx, want.camera.cx);
  EXPECT_EQ(got.camera.cy, want.camera.cy);
  EXPECT_EQ(got.camera.distortion, want.camera.distortion);
  EXPECT_EQ(got.camera.distortion_coeffs, want.camera.distortion_coeffs);
}

TEST(SimBagConfig, EverySectionButDatasetAndCalibrationIsFarmSims) {
  const YAML::Node bag = YAML::LoadFile(config("farm_sim_bag.yaml")), folder = YAML::LoadFile(config("farm_sim.yaml"));
  std::size_t compared = 0;
  for (const auto& kv : folder) {
    const std::string section = kv.first.Scalar();
    if (section == "dataset" || section == "calibration") continue;
    ASSERT_TRUE(bag[section]) << "farm_sim_bag.yaml lacks farm_sim.yaml's section " << section;
    EXPECT_EQ(YAML::Dump(bag[section]), YAML::Dump(kv.second)) << "section " << section << " differs";
    ++compared;
  }
  EXPECT_GE(compared, 5u);  // sim, odometry, loop, visual, vio
  for (const auto& kv : bag) {
    const std::string section = kv.first.Scalar();
    EXPECT_TRUE(section == "dataset" || section == "calibration" || folder[section]) << section;
  }
}

}  // namespace
}  // namespace drover::io
