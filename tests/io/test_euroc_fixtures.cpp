// EuRoC reader on tiny sequences written by the tests: known answers, and every kind of corrupted input.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "io/error.hpp"
#include "io/euroc_reader.hpp"
#include "support/expect_io_error.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;

const char* kImuYaml = R"(%YAML:1.0
sensor_type: imu
T_BS:
  cols: 4
  rows: 4
  data: [1.0, 0.0, 0.0, 0.0,
         0.0, 1.0, 0.0, 0.0,
         0.0, 0.0, 1.0, 0.0,
         0.0, 0.0, 0.0, 1.0]
rate_hz: 200
)";

// Camera rotated +90 deg about z and shifted (1, 2, 3) m in the body frame.
const char* kCamYaml = R"(%YAML:1.0
sensor_type: camera
T_BS:
  cols: 4
  rows: 4
  data: [0.0, -1.0, 0.0, 1.0,
         1.0, 0.0, 0.0, 2.0,
         0.0, 0.0, 1.0, 3.0,
         0.0, 0.0, 0.0, 1.0]
rate_hz: 20
resolution: [4, 3]
camera_model: pinhole
intrinsics: [100.0, 101.0, 2.0, 1.5] #fu, fv, cu, cv
distortion_model: radial-tangential
distortion_coefficients: [0.1, -0.01, 0.001, 0.0001]
)";

const char* kImuCsv =
    "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],"
    "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n"
    "1000,0.1,0.2,0.3,1.0,2.0,9.81\n"
    "2000,0.4,0.5,0.6,1.5,2.5,9.80\n"
    "3000,-0.1,-0.2,-0.3,-1.0,-2.0,-9.81\n";

const char* kCamCsv = "#timestamp [ns],filename\n2000,2000.pgm\n4000,4000.pgm\n";

// A 4x3 binary PGM whose pixel i is base + i (OpenCV decodes it like any PNG).
std::string pgm(int base, int width = 4, int height = 3) {
  std::string s = "P5\n" + std::to_string(width) + " " + std::to_string(height) + "\n255\n";
  for (int i = 0; i < width * height; ++i) s.push_back(static_cast<char>(base + i));
  return s;
}

class EurocFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    write("mav0/imu0/sensor.yaml", kImuYaml);
    write("mav0/cam0/sensor.yaml", kCamYaml);
    write("mav0/imu0/data.csv", kImuCsv);
    write("mav0/cam0/data.csv", kCamCsv);
    write("mav0/cam0/data/2000.pgm", pgm(10));
    write("mav0/cam0/data/4000.pgm", pgm(100));
  }
  void write(const std::string& rel, const std::string& text) { test::writeText(dir_ / rel, text); }
  std::string seq() const { return dir_.path().string(); }
  fs::path path(const std::string& rel) const { return dir_ / rel; }

  // The IoError message of opening (and, with `stream`, reading) the fixture; fails the test if none is thrown.
  std::string errorOf(bool stream = false) {
    try {
      auto reader = openEuroc(seq(), DatasetOptions{});
      while (stream && reader->next()) {
      }
    } catch (const IoError& e) {
      return e.what();
    }
    ADD_FAILURE() << "expected an IoError";
    return "";
  }

  test::TempDir dir_;
};

bool hasText(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST_F(EurocFixture, MergesImuAndImagesInTimeOrderImuFirstOnTies) {
  auto reader = openEuroc(seq(), DatasetOptions{});
  std::vector<std::pair<char, Time>> order;
  std::vector<CameraFrame> frames;
  while (auto m = reader->next()) {
    const bool is_imu = std::holds_alternative<ImuSample>(*m);
    order.emplace_back(is_imu ? 'i' : 'c', measurementTime(*m));
    if (!is_imu) frames.push_back(std::get<CameraFrame>(*m));
  }
  const std::vector<std::pair<char, Time>> expected{{'i', 1000}, {'i', 2000}, {'c', 2000}, {'i', 3000}, {'c', 4000}};
  EXPECT_EQ(order, expected);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].image.width, 4);
  EXPECT_EQ(frames[0].image.height, 3);
  EXPECT_EQ(frames[0].image.channels, 1);
  EXPECT_EQ(frames[0].image.data[0], 10);
  EXPECT_EQ(frames[0].image.data[11], 21);
  EXPECT_EQ(frames[1].image.data[5], 105);
}

TEST_F(EurocFixture, ReadsImuValuesInRadPerSecondAndMetresPerSecondSquared) {
  DatasetOptions options;
  options.load_images = false;
  auto reader = openEuroc(seq(), options);
  const auto m = reader->next();
  ASSERT_TRUE(m && std::holds_alternative<ImuSample>(*m));
  const auto& s = std::get<ImuSample>(*m);
  EXPECT_EQ(s.t, 1000);
  EXPECT_EQ(s.omega_imu, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(s.acc_imu, Eigen::Vector3d(1.0, 2.0, 9.81));
}

TEST_F(EurocFixture, ComposesTimuCamFromBothSensorYamls) {
  // IMU rotated -90 deg about x and shifted (0.5, 0, 0) in the body frame.
  std::string imu = kImuYaml;
  imu.replace(imu.find("data: ["), std::string::npos,
              "data: [1, 0, 0, 0.5,  0, 0, 1, 0,  0, -1, 0, 0,  0, 0, 0, 1]\n");
  write("mav0/imu0/sensor.yaml", imu);
  const Calibration c = readEurocCalibration(path("mav0").string());
  Eigen::Isometry3d T_B_imu = Eigen::Isometry3d::Identity();
  T_B_imu.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  T_B_imu.translation() = Eigen::Vector3d(0.5, 0, 0);
  Eigen::Isometry3d T_B_cam = Eigen::Isometry3d::Identity();
  T_B_cam.linear() << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  T_B_cam.translation() = Eigen::Vector3d(1, 2, 3);
  // A camera point must land on the same body point through either chain.
  const Eigen::Vector3d p_cam(0.3, -0.7, 2.0);
  EXPECT_TRUE((T_B_imu * (c.T_imu_cam * p_cam)).isApprox(T_B_cam * p_cam, 1e-12));
  // Camera origin in the IMU frame, by hand: R_B_imu^T ((1,2,3) - (0.5,0,0)) = (0.5, -3, 2).
  EXPECT_TRUE(c.T_imu_cam.translation().isApprox(Eigen::Vector3d(0.5, -3, 2), 1e-12));
  EXPECT_EQ(c.camera.fx, 100.0);
  EXPECT_EQ(c.camera.cy, 1.5);
}

TEST_F(EurocFixture, PrefersTheGroundTruthCsvOverTheTumFile) {
  write("mav0/state_groundtruth_estimate0/data.csv",
        "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z []\n"
        "1500,1.0,2.0,3.0,1.0,0.0,0.0,0.0\n2500,1.5,2.0,3.0,1.0,0.0,0.0,0.0\n");
  write("groundtruth_tum.txt", "0.000001 9 9 9 0 0 0 1\n");
  const auto reader = openEuroc(seq(), DatasetOptions{});
  const GroundTruth& gt = reader->groundTruth();
  ASSERT_EQ(gt.poses.size(), 2u);
  EXPECT_EQ(gt.body_frame, "imu");
  EXPECT_EQ(gt.poses[0].t, 1500);
  EXPECT_TRUE(gt.poses[1].T_world_body.translation().isApprox(Eigen::Vector3d(1.5, 2.0, 3.0)));
}

TEST_F(EurocFixture, FallsBackToTheTumFileAndHasNoGroundTruthWithoutEither) {
  EXPECT_TRUE(openEuroc(seq(), DatasetOptions{})->groundTruth().poses.empty());
  write("groundtruth_tum.txt", "# t x y z qx qy qz qw\n0.000001 9 8 7 0 0 0 1\n");
  const auto reader = openEuroc(seq(), DatasetOptions{});
  ASSERT_EQ(reader->groundTruth().poses.size(), 1u);
  EXPECT_EQ(reader->groundTruth().poses[0].t, 1000);
  EXPECT_TRUE(reader->groundTruth().poses[0].T_world_body.translation().isApprox(Eigen::Vector3d(9, 8, 7)));
}

TEST_F(EurocFixture, AcceptsEquidistantDistortion) {
  std::string cam = kCamYaml;
  cam.replace(cam.find("distortion_model"), std::string::npos,
              "distortion_model: equidistant\ndistortion_coefficients: [0.01, 0.02, 0.03, 0.04]\n");
  write("mav0/cam0/sensor.yaml", cam);
  const Calibration c = readEurocCalibration(path("mav0").string());
  EXPECT_EQ(c.camera.distortion, DistortionModel::kEquidistant);
  EXPECT_EQ(c.camera.distortion_coeffs, (std::vector<double>{0.01, 0.02, 0.03, 0.04}));
}

TEST_F(EurocFixture, RejectsAMissingFolder) {
  const std::string missing = (dir_ / "nope").string();
  try {
    openEuroc(missing, DatasetOptions{});
    FAIL() << "expected an IoError";
  } catch (const IoError& e) {
    EXPECT_TRUE(hasText(e.what(), missing)) << e.what();
  }
}

TEST_F(EurocFixture, RejectsAFolderWithoutMav0) {
  fs::remove_all(path("mav0"));
  fs::create_directories(path("other"));
  EXPECT_TRUE(hasText(errorOf(), "no mav0/"));
}

TEST_F(EurocFixture, RejectsAMissingSensorYaml) {
  fs::remove(path("mav0/imu0/sensor.yaml"));
  const std::string msg = errorOf();
  EXPECT_TRUE(hasText(msg, "imu0/sensor.yaml")) << msg;
  EXPECT_TRUE(hasText(msg, "not found")) << msg;
}

TEST_F(EurocFixture, RejectsASensorYamlWithoutIntrinsics) {
  std::string cam = kCamYaml;
  cam.erase(cam.find("intrinsics:"), cam.find('\n', cam.find("intrinsics:")) - cam.find("intrinsics:") + 1);
  write("mav0/cam0/sensor.yaml", cam);
  const std::string msg = errorOf();
  EXPECT_TRUE(hasText(msg, "cam0/sensor.yaml")) << msg;
  EXPECT_TRUE(hasText(msg, "key 'intrinsics'")) << msg;
  EXPECT_TRUE(hasText(msg, "missing")) << msg;
}

TEST_F(EurocFixture, RejectsTbsWithFifteenNumbers) {
  std::string cam = kCamYaml;
  cam.replace(cam.find("0.0, 0.0, 0.0, 1.0]"), 19, "0.0, 0.0, 1.0]");
  write("mav0/cam0/sensor.yaml", cam);
  const std::string msg = errorOf();
  EXPECT_TRUE(hasText(msg, "T_BS.data")) << msg;
  EXPECT_TRUE(hasText(msg, "expected 16 numbers, found 15")) << msg;
}

TEST_F(EurocFixture, RejectsTbsWhoseRotationIsNotARotation) {
  std::string cam = kCamYaml;
  cam.replace(cam.find("[0.0, -1.0"), 10, "[0.0, -2.0");
  write("mav0/cam0/sensor.yaml", cam);
  EXPECT_TRUE(hasText(errorOf(), "not orthonormal"));
}

TEST_F(EurocFixture, RejectsAnUnknownDistortionModel) {
  std::string cam = kCamYaml;
  cam.replace(cam.find("radial-tangential"), 17, "fisheye62");
  write("mav0/cam0/sensor.yaml", cam);
  EXPECT_TRUE(hasText(errorOf(), "unknown distortion model 'fisheye62'"));
}

TEST_F(EurocFixture, RejectsAnImuLineWithSixColumns) {
  write("mav0/imu0/data.csv", "#header\n1000,0.1,0.2,0.3,1.0,2.0,9.81\n2000,0.1,0.2,0.3,1.0,2.0\n");
  const std::string msg = errorOf();
  EXPECT_TRUE(hasText(msg, "imu0/data.csv (line 3)")) << msg;
  EXPECT_TRUE(hasText(msg, "expected 7 columns, found 6")) << msg;
}

TEST_F(EurocFixture, RejectsAZeroOrNonFiniteFocalLengthNamingTheKey) {
  std::string cam = kCamYaml;
  cam.replace(cam.find("intrinsics: [100.0"), 18, "intrinsics: [0.0");
  write("mav0/cam0/sensor.yaml", cam);
  std::string msg = errorOf();
  EXPECT_TRUE(hasText(msg, "cam0/sensor.yaml (line 13, key 'intrinsics')")) << msg;
  EXPECT_TRUE(hasText(msg, "focal lengths must be > 0 px, got fx 0, fy 101")) << msg;
  cam.replace(cam.find("intrinsics: [0.0"), 16, "intrinsics: [.nan");
  write("mav0/cam0/sensor.yaml", cam);
  msg = errorOf();
  EXPECT_TRUE(hasText(msg, "cam0/sensor.yaml (line 13, key 'intrinsics')")) << msg;
}

TEST_F(EurocFixture, ImuNoiseFiguresTheSensorYamlLeavesOutAreEmpty) {
  write("mav0/imu0/sensor.yaml", std::string(kImuYaml) + "gyroscope_noise_density: 1.5e-4\n");
  const EurocImuNoise noise = readEurocImuNoise(seq());
  EXPECT_TRUE(hasText(noise.file, "mav0/imu0/sensor.yaml")) << noise.file;
  EXPECT_EQ(noise.gyroscope_noise_density, 1.5e-4);
  EXPECT_FALSE(noise.gyroscope_random_walk.has_value());
  EXPECT_FALSE(noise.accelerometer_noise_density.has_value());
  EXPECT_FALSE(noise.accelerometer_random_walk.has_value());
}

TEST_F(EurocFixture, RejectsANegativeOrNonNumericImuNoiseFigureNamingTheKey) {
  write("mav0/imu0/sensor.yaml", std::string(kImuYaml) + "accelerometer_random_walk: -3.0e-3\n");
  test::expectIoError([&] { readEurocImuNoise(seq()); },
                      {"imu0/sensor.yaml (line 11, key 'accelerometer_random_walk')",
                       "expected a noise density >= 0, got -0.003"});
  write("mav0/imu0/sensor.yaml", std::string(kImuYaml) + "gyroscope_random_walk: [1, 2]\n");
  test::expectIoError([&] { readEurocImuNoise(seq()); }, {"key 'gyroscope_random_walk'", "expected a single value"});
}

TEST_F(EurocFixture, RejectsNanInAnImuLine) {
  write("mav0/imu0/data.csv", "1000,0.1,nan,0.3,1.0,2.0,9.81\n");
  const std::string msg = errorOf();
  EXPECT_TRUE(hasText(msg, "imu0/data.csv (line 1)")) << msg;
  EXPECT_TRUE(hasText(msg, "nan")) << msg;
}

TEST_F(EurocFixture, DropsImuRowsWhoseStampGoesBackwardsWithACountedWarning) {
  write("mav0/imu0/data.csv", "2000,0,0,0,0,0,9.81\n1000,0,0,0,0,0,9.81\n3000,0,0,0,0,0,9.81\n");
  DatasetOptions options;
  options.load_images = false;
  const auto reader = openEuroc(seq(), options);
  std::vector<Time> t;
  while (auto m = reader->next()) t.push_back(measurementTime(*m));
  EXPECT_EQ(t, (std::vector<Time>{2000, 3000}));
  ASSERT_EQ(reader->drops().measurements, 1u);
  const std::string& msg = reader->drops().notices.at(0);
  EXPECT_TRUE(hasText(msg, "imu0/data.csv (line 2): dropped: timestamp goes back")) << msg;
}

TEST_F(EurocFixture, DropsAnImageWhoseStampRepeatsWithACountedWarning) {
  write("mav0/cam0/data.csv", "#timestamp [ns],filename\n2000,2000.pgm\n2000,4000.pgm\n");
  DatasetOptions options;
  options.load_imu = false;
  const auto reader = openEuroc(seq(), options);
  std::vector<Time> t;
  while (auto m = reader->next()) t.push_back(measurementTime(*m));
  EXPECT_EQ(t, (std::vector<Time>{2000}));
  ASSERT_EQ(reader->drops().measurements, 1u);
  const std::string& msg = reader->drops().notices.at(0);
  EXPECT_TRUE(hasText(msg, "cam0/data.csv (line 3): dropped: timestamp 0.000002000 s repeats")) << msg;
}

TEST_F(EurocFixture, RejectsAListedImageThatIsMissingWhenItIsRead) {
  fs::remove(path("mav0/cam0/data/4000.pgm"));
  auto reader = openEuroc(seq(), DatasetOptions{});  // opening only indexes: no error yet
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(reader->next().has_value());  // up to the IMU sample at 3000
  try {
    reader->next();
    FAIL() << "expected an IoError";
  } catch (const IoError& e) {
    EXPECT_TRUE(hasText(e.what(), "4000.pgm")) << e.what();
    EXPECT_TRUE(hasText(e.what(), "cam0/data.csv line 3")) << e.what();
    EXPECT_TRUE(hasText(e.what(), "not found")) << e.what();
  }
}

TEST_F(EurocFixture, RejectsAnImageOfTheWrongSize) {
  write("mav0/cam0/data/2000.pgm", pgm(0, 5, 3));
  const std::string msg = errorOf(/*stream=*/true);
  EXPECT_TRUE(hasText(msg, "2000.pgm")) << msg;
  EXPECT_TRUE(hasText(msg, "5x3")) << msg;
}

TEST_F(EurocFixture, RejectsAnUndecodableImage) {
  write("mav0/cam0/data/2000.pgm", "not an image");
  EXPECT_TRUE(hasText(errorOf(/*stream=*/true), "cannot decode image"));
}

}  // namespace
}  // namespace drover::io
