// Platform config files: every file in config/ loads, known values come through, and typos or wrong types are
// errors naming file and key.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "io/config.hpp"
#include "io/error.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;

const fs::path kConfigDir = fs::path(DROVER_SOURCE_DIR) / "config";

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// The IoError message of loading `yaml` from a file; fails the test if none is thrown.
std::string errorOf(const std::string& yaml, std::string* file_out = nullptr) {
  test::TempDir dir;
  const fs::path file = dir / "platform.yaml";
  test::writeText(file, yaml);
  if (file_out) *file_out = file.string();
  try {
    loadDatasetOptions(file.string());
  } catch (const IoError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an IoError for:\n" << yaml;
  return "";
}

DatasetOptions load(const std::string& yaml) {
  test::TempDir dir;
  test::writeText(dir / "platform.yaml", yaml);
  return loadDatasetOptions((dir / "platform.yaml").string());
}

TEST(Config, EveryPlatformFileLoads) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(kConfigDir)) {
    if (entry.path().extension() != ".yaml") continue;
    names.insert(entry.path().filename().string());
    EXPECT_NO_THROW(loadDatasetOptions(entry.path().string())) << entry.path();
  }
  for (const char* required : {"kitti.yaml", "kitti_raw.yaml", "euroc.yaml", "m2dgr.yaml", "lvisam.yaml",
                               "farm_sim.yaml", "farm_sim_bag.yaml", "car_sim.yaml"})
    EXPECT_EQ(names.count(required), 1u) << required;
}

TEST(Config, M2dgrHasItsTopicsAndPublishedCalibration) {
  const DatasetOptions o = loadDatasetOptions((kConfigDir / "m2dgr.yaml").string());
  EXPECT_EQ(o.lidar_topic, "/velodyne_points");
  EXPECT_EQ(o.imu_topic, "/handsfree/imu");
  EXPECT_EQ(o.image_topic, "/camera/color/image_raw/compressed");
  const Calibration& c = o.calibration;
  EXPECT_TRUE(c.T_imu_lidar.linear().isApprox(Eigen::Matrix3d::Identity()));
  EXPECT_TRUE(c.T_imu_lidar.translation().isApprox(Eigen::Vector3d(0.27255, -0.00053, 0.17954)));
  // T_imu_cam must equal inv(T_lidar_imu) * T_lidar_cam from calibration_results.txt.
  Eigen::Isometry3d T_lidar_imu = Eigen::Isometry3d::Identity();
  T_lidar_imu.translation() = Eigen::Vector3d(-0.27255, 0.00053, -0.17954);
  Eigen::Isometry3d T_lidar_cam = Eigen::Isometry3d::Identity();
  T_lidar_cam.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T_lidar_cam.translation() = Eigen::Vector3d(0.30456, 0.00065, 0.65376);
  EXPECT_TRUE(c.T_imu_cam.isApprox(T_lidar_imu.inverse() * T_lidar_cam, 1e-12));
  EXPECT_EQ(c.camera.width, 640);
  EXPECT_EQ(c.camera.height, 480);
  EXPECT_DOUBLE_EQ(c.camera.fx, 617.971050917033);
  EXPECT_DOUBLE_EQ(c.camera.cy, 253.976983707814);
  EXPECT_EQ(c.camera.distortion, DistortionModel::kRadialTangential);
  EXPECT_EQ(c.camera.distortion_coeffs.size(), 4u);
}

TEST(Config, LvisamHasItsBagTopicsAndExtrinsics) {
  const DatasetOptions o = loadDatasetOptions((kConfigDir / "lvisam.yaml").string());
  EXPECT_EQ(o.lidar_topic, "/points_raw");
  EXPECT_EQ(o.imu_topic, "/imu_raw");
  EXPECT_EQ(o.image_topic, "/camera/image_raw");
  const Eigen::Matrix3d flip = Eigen::Vector3d(-1, 1, -1).asDiagonal();
  EXPECT_TRUE(o.calibration.T_imu_lidar.linear().isApprox(flip));
  Eigen::Matrix3d R_imu_cam;
  R_imu_cam << 0, 0, -1, -1, 0, 0, 0, 1, 0;
  EXPECT_TRUE(o.calibration.T_imu_cam.linear().isApprox(R_imu_cam));
  EXPECT_DOUBLE_EQ(o.calibration.T_imu_cam.translation().z(), 0.03364235163589248);
  EXPECT_EQ(o.calibration.camera.width, 0);  // MEI model: deliberately not given
}

TEST(Config, DatasetFilesSelectTheirSensors) {
  const DatasetOptions kitti = loadDatasetOptions((kConfigDir / "kitti.yaml").string());
  EXPECT_EQ(kitti.kitti_camera, 2);
  EXPECT_FALSE(kitti.load_imu);
  const DatasetOptions euroc = loadDatasetOptions((kConfigDir / "euroc.yaml").string());
  EXPECT_FALSE(euroc.load_lidar);
  EXPECT_TRUE(euroc.load_imu);
}

TEST(Config, AbsentSectionsAndKeysKeepTheDefaults) {
  const DatasetOptions defaults;
  for (const char* yaml : {"", "sim:\n  noise: false\nodometry:\n  use_imu: false\n", "dataset:\ncalibration:\n"}) {
    const DatasetOptions o = load(yaml);
    EXPECT_EQ(o.lidar_topic, defaults.lidar_topic) << yaml;
    EXPECT_EQ(o.kitti_camera, defaults.kitti_camera) << yaml;
    EXPECT_EQ(o.load_images, defaults.load_images) << yaml;
    EXPECT_TRUE(o.calibration.T_imu_cam.isApprox(Eigen::Isometry3d::Identity())) << yaml;
  }
}

TEST(Config, UnknownTopLevelSectionIsNamedWithItsLine) {
  const std::string e = errorOf("dataset:\n  load_imu: true\nodometri:\n  use_imu: false\n");
  EXPECT_NE(e.find("line 3"), std::string::npos) << e;
  EXPECT_NE(e.find("'odometri'"), std::string::npos) << e;
  EXPECT_NE(e.find("odometry"), std::string::npos) << e;  // the known sections are listed
}

TEST(Config, ReadsEveryKey) {
  const DatasetOptions o = load(R"(
dataset:
  lidar_topic: /l
  imu_topic: /i
  image_topic: /c
  kitti_camera: 0
  load_lidar: false
  load_imu: false
  load_images: false
calibration:
  T_imu_lidar: [1, 0, 0, 1, 0, 1, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1]
  camera: {width: 10, height: 8, fx: 5, fy: 6, cx: 4.5, cy: 3.5, distortion_model: equidistant,
           distortion_coeffs: [0.1, 0.2, 0.3, 0.4]}
  lidar_time_offset: -0.0125
  camera_time_offset: 0.000000001
)");
  EXPECT_EQ(o.lidar_topic, "/l");
  EXPECT_EQ(o.imu_topic, "/i");
  EXPECT_EQ(o.image_topic, "/c");
  EXPECT_EQ(o.kitti_camera, 0);
  EXPECT_FALSE(o.load_lidar || o.load_imu || o.load_images);
  EXPECT_EQ(o.calibration.T_imu_lidar.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(o.calibration.camera.width, 10);
  EXPECT_EQ(o.calibration.camera.cx, 4.5);
  EXPECT_EQ(o.calibration.camera.distortion, DistortionModel::kEquidistant);
  EXPECT_EQ(o.calibration.lidar_time_offset, -12'500'000);  // seconds in the file, nanoseconds in memory
  EXPECT_EQ(o.calibration.camera_time_offset, 1);
}

TEST(Config, RejectsAMissingFile) {
  try {
    loadDatasetOptions("/nonexistent/platform.yaml");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_TRUE(contains(e.what(), "/nonexistent/platform.yaml")) << e.what();
  }
}

TEST(Config, RejectsInvalidYamlNamingTheLine) {
  const std::string msg = errorOf("dataset:\n  lidar_topic: [a, b\n");
  EXPECT_TRUE(contains(msg, "invalid YAML")) << msg;
  EXPECT_TRUE(contains(msg, "line ")) << msg;
}

TEST(Config, RejectsAnUnknownDatasetKeyNamingIt) {
  std::string file;
  const std::string msg = errorOf("dataset:\n  load_imu: true\n  lidar_topc: /x\n", &file);
  EXPECT_TRUE(contains(msg, file)) << msg;
  EXPECT_TRUE(contains(msg, "line 3, key 'dataset.lidar_topc'")) << msg;
  EXPECT_TRUE(contains(msg, "unknown key")) << msg;
}

TEST(Config, RejectsAnUnknownCameraKeyNamingIt) {
  const std::string msg = errorOf("calibration:\n  camera:\n    focal: 500\n");
  EXPECT_TRUE(contains(msg, "key 'calibration.camera.focal'")) << msg;
}

TEST(Config, RejectsWrongTypesNamingFileAndKey) {
  std::string file;
  std::string msg = errorOf("dataset:\n  load_imu: maybe\n", &file);
  EXPECT_TRUE(contains(msg, file)) << msg;
  EXPECT_TRUE(contains(msg, "key 'dataset.load_imu'")) << msg;
  EXPECT_TRUE(contains(msg, "expected true or false, found 'maybe'")) << msg;

  msg = errorOf("dataset:\n  kitti_camera: left\n");
  EXPECT_TRUE(contains(msg, "key 'dataset.kitti_camera'")) << msg;
  msg = errorOf("dataset:\n  kitti_camera: 7\n");
  EXPECT_TRUE(contains(msg, "out of range (expected an integer in [0, 3])")) << msg;
  msg = errorOf("dataset:\n  lidar_topic: [/a, /b]\n");
  EXPECT_TRUE(contains(msg, "key 'dataset.lidar_topic'")) << msg;
  msg = errorOf("calibration:\n  camera:\n    fx: [1, 2]\n");
  EXPECT_TRUE(contains(msg, "key 'calibration.camera.fx'")) << msg;
  msg = errorOf("calibration:\n  lidar_time_offset: soon\n");
  EXPECT_TRUE(contains(msg, "key 'calibration.lidar_time_offset'")) << msg;
  msg = errorOf("dataset: [1, 2]\n");
  EXPECT_TRUE(contains(msg, "key 'dataset'")) << msg;
}

TEST(Config, RejectsTransformsThatAreNotRigid) {
  std::string msg = errorOf("calibration:\n  T_imu_cam: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0]\n");
  EXPECT_TRUE(contains(msg, "key 'calibration.T_imu_cam'")) << msg;
  EXPECT_TRUE(contains(msg, "expected 16 numbers")) << msg;
  msg = errorOf("calibration:\n  T_imu_lidar: [2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n");
  EXPECT_TRUE(contains(msg, "not orthonormal")) << msg;
  msg = errorOf("calibration:\n  T_imu_lidar: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1]\n");
  EXPECT_TRUE(contains(msg, "last row")) << msg;
  msg = errorOf("calibration:\n  T_imu_lidar: [1, 0, 0, .nan, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n");
  EXPECT_TRUE(contains(msg, "key 'calibration.T_imu_lidar'")) << msg;
}

TEST(Config, RejectsDistortionCoefficientsThatDoNotFitTheModel) {
  const std::string msg =
      errorOf("calibration:\n  camera:\n    distortion_model: equidistant\n    distortion_coeffs: [0.1, 0.2]\n");
  EXPECT_TRUE(contains(msg, "2 coefficients do not fit")) << msg;
  EXPECT_TRUE(contains(errorOf("calibration:\n  camera:\n    distortion_model: fisheye\n"),
                       "unknown distortion model 'fisheye'"));
}

TEST(Config, AFolderGivenAsTheConfigIsAnErrorNotTheDefaults) {
  test::TempDir dir;
  try {
    loadDatasetOptions(dir.path().string());
    ADD_FAILURE() << "a folder loaded as a config";
  } catch (const IoError& e) {
    EXPECT_TRUE(contains(e.what(), dir.path().string())) << e.what();
    EXPECT_TRUE(contains(e.what(), "is a folder")) << e.what();
  }
}

TEST(Config, AKeyWrittenTwiceIsAnErrorNamingBothLines) {
  const std::string msg = errorOf("dataset:\n  load_imu: false\n  load_lidar: true\n  load_imu: true\n");
  EXPECT_TRUE(contains(msg, "line 4, key 'dataset.load_imu'")) << msg;
  EXPECT_TRUE(contains(msg, "duplicate key (first at line 2)")) << msg;
  const std::string nested =
      errorOf("calibration:\n  camera:\n    fx: 500\n    fy: 500\n    fx: 400\n");
  EXPECT_TRUE(contains(nested, "line 5, key 'calibration.camera.fx'")) << nested;
}

TEST(Config, ASectionWrittenTwiceIsAnErrorNamingBothLines) {
  const std::string msg = errorOf("dataset:\n  load_imu: false\nsim:\n  noise: false\ndataset:\n  load_imu: true\n");
  EXPECT_TRUE(contains(msg, "line 5, section 'dataset'")) << msg;
  EXPECT_TRUE(contains(msg, "duplicate section (first at line 1)")) << msg;
}

TEST(Config, DuplicateKeysInSectionsOfOtherModulesAreCaughtToo) {
  // loadConfigRoot is shared by every section's reader, so the dataset reader also sees odometry's duplicates.
  const std::string msg = errorOf("odometry:\n  matcher:\n    neighbors: 5\n    neighbors: 6\n");
  EXPECT_TRUE(contains(msg, "line 4, key 'odometry.matcher.neighbors'")) << msg;
}

TEST(Config, TimeOffsetsAreCheckedSecondsNamingTheRange) {
  const std::string msg = errorOf("calibration:\n  camera_time_offset: 1e10\n");
  EXPECT_TRUE(contains(msg, "line 2, key 'calibration.camera_time_offset'")) << msg;
  EXPECT_TRUE(contains(msg, "expected [-3600, 3600] s")) << msg;
  for (const char* nan : {".nan", "nan", "-inf"}) {
    const std::string e = errorOf(std::string("calibration:\n  lidar_time_offset: ") + nan + "\n");
    EXPECT_TRUE(contains(e, "key 'calibration.lidar_time_offset'") && contains(e, nan)) << e;
  }
}

TEST(Config, AHugeValueIsEchoedShortened) {
  const std::string huge(1'000'000, 'x');
  const std::string msg = errorOf("dataset:\n  load_imu: " + huge + "\n");
  EXPECT_LT(msg.size(), 400u) << msg.substr(0, 400);
  EXPECT_TRUE(contains(msg, "(1000000 characters)")) << msg.substr(0, 400);
  const std::string key = errorOf("dataset:\n  " + huge + ": 1\n");
  EXPECT_LT(key.size(), 600u) << key.substr(0, 600);
}

}  // namespace
}  // namespace drover::io
