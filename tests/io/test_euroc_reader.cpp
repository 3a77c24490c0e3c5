// EuRoC reader on the real V1_01_easy snippet in ../shared. Expected values were read from the files by hand
// (and pixel statistics with PIL), not through the reader.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>

#include "io/euroc_reader.hpp"
#include "support/shared_data.hpp"

namespace drover::io {
namespace {

const std::filesystem::path kSeq = test::sharedData("euroc/V1_01_easy_micro");

struct Stream {
  std::vector<ImuSample> imu;
  std::vector<CameraFrame> frames;
  std::vector<Time> times;          // every measurement, in stream order
  std::vector<char> kinds;          // 'i' or 'c', in stream order
};

Stream readStream(Reader& reader) {
  Stream s;
  while (auto m = reader.next()) {
    s.times.push_back(measurementTime(*m));
    if (auto* imu = std::get_if<ImuSample>(&*m)) {
      s.imu.push_back(*imu);
      s.kinds.push_back('i');
    } else if (auto* frame = std::get_if<CameraFrame>(&*m)) {
      s.frames.push_back(std::move(*frame));
      s.kinds.push_back('c');
    } else {
      ADD_FAILURE() << "EuRoC has no lidar";
    }
  }
  return s;
}

std::uint64_t pixelSum(const Image& img) {
  return std::accumulate(img.data.begin(), img.data.end(), std::uint64_t{0});
}

TEST(EurocReader, StreamsAllImuSamplesAndFramesOfTheSnippet) {
  DROVER_REQUIRE_SHARED(kSeq);
  auto reader = openEuroc(kSeq.string(), DatasetOptions{});
  const Stream s = readStream(*reader);
  EXPECT_EQ(s.imu.size(), 29120u);  // 200 Hz over 145.6 s
  ASSERT_EQ(s.frames.size(), 95u);  // 20 Hz over 4.7 s
  EXPECT_EQ(reader->describe(), "EuRoC V1_01_easy_micro");
}

TEST(EurocReader, FirstAndLastImuSamplesMatchTheCsv) {
  DROVER_REQUIRE_SHARED(kSeq);
  DatasetOptions options;
  options.load_images = false;
  const Stream s = readStream(*openEuroc(kSeq.string(), options));
  ASSERT_EQ(s.imu.size(), 29120u);
  const ImuSample& first = s.imu.front();
  EXPECT_EQ(first.t, 1403715273262142976);
  EXPECT_DOUBLE_EQ(first.omega_imu.x(), -0.0020943951023931952);
  EXPECT_DOUBLE_EQ(first.omega_imu.y(), 0.017453292519943295);
  EXPECT_DOUBLE_EQ(first.omega_imu.z(), 0.07749261878854824);
  EXPECT_DOUBLE_EQ(first.acc_imu.x(), 9.0874956666666655);
  EXPECT_DOUBLE_EQ(first.acc_imu.y(), 0.13075533333333333);
  EXPECT_DOUBLE_EQ(first.acc_imu.z(), -3.6938381666666662);
  const ImuSample& last = s.imu.back();
  EXPECT_EQ(last.t, 1403715418857143040);
  EXPECT_DOUBLE_EQ(last.omega_imu.x(), -0.00069813170079773186);
  EXPECT_DOUBLE_EQ(last.omega_imu.z(), 0.074001960284559576);
  EXPECT_DOUBLE_EQ(last.acc_imu.x(), 9.1610455416666667);
  EXPECT_DOUBLE_EQ(last.acc_imu.z(), -3.2035056666666666);
  EXPECT_FALSE(first.q_world_imu.has_value());  // the ADIS16448 gives no orientation
}

TEST(EurocReader, ImagesAreMono8At752x480WithThePixelsOfThePng) {
  DROVER_REQUIRE_SHARED(kSeq);
  DatasetOptions options;
  options.load_imu = false;
  const Stream s = readStream(*openEuroc(kSeq.string(), options));
  ASSERT_EQ(s.frames.size(), 95u);
  const CameraFrame& first = s.frames.front();
  EXPECT_EQ(first.t, 1403715273262142976);
  EXPECT_EQ(first.image.width, 752);
  EXPECT_EQ(first.image.height, 480);
  EXPECT_EQ(first.image.channels, 1);
  ASSERT_EQ(first.image.data.size(), 752u * 480u);
  // PIL: pixel (row 0, col 0) = 77, (240, 376) = 89, (479, 751) = 190; sum of all pixels 52381130.
  EXPECT_EQ(first.image.data[0], 77);
  EXPECT_EQ(first.image.data[240 * 752 + 376], 89);
  EXPECT_EQ(first.image.data[479 * 752 + 751], 190);
  EXPECT_EQ(pixelSum(first.image), 52381130u);
  EXPECT_NE(first.source.find("1403715273262142976.png"), std::string::npos);
  const CameraFrame& last = s.frames.back();
  EXPECT_EQ(last.t, 1403715277962142976);
  EXPECT_EQ(pixelSum(last.image), 52658927u);
}

TEST(EurocReader, MergesInTimeOrderWithImuFirstOnEqualStamps) {
  DROVER_REQUIRE_SHARED(kSeq);
  const Stream s = readStream(*openEuroc(kSeq.string(), DatasetOptions{}));
  ASSERT_EQ(s.times.size(), 29120u + 95u);
  EXPECT_TRUE(std::is_sorted(s.times.begin(), s.times.end()));
  // The first IMU sample and the first image share the stamp 1403715273262142976: IMU comes first.
  ASSERT_GE(s.kinds.size(), 2u);
  EXPECT_EQ(s.kinds[0], 'i');
  EXPECT_EQ(s.kinds[1], 'c');
  EXPECT_EQ(s.times[0], s.times[1]);
}

TEST(EurocReader, CalibrationIsTheCameraTbsBecauseTheImuIsTheBody) {
  DROVER_REQUIRE_SHARED(kSeq);
  auto reader = openEuroc(kSeq.string(), DatasetOptions{});
  const Calibration& c = reader->calibration();
  // cam0/sensor.yaml T_BS, row-major; imu0/sensor.yaml T_BS is identity, so T_imu_cam = T_B_cam.
  const double T_BS[16] = {0.0148655429818,  -0.999880929698, 0.00414029679422, -0.0216401454975,
                           0.999557249008,   0.0149672133247, 0.025715529948,   -0.064676986768,
                           -0.0257744366974, 0.00375618835797, 0.999660727178,  0.00981073058949,
                           0.0,              0.0,              0.0,             1.0};
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col)
      EXPECT_NEAR(c.T_imu_cam.matrix()(r, col), T_BS[4 * r + col], 1e-8) << "row " << r << " col " << col;
  EXPECT_TRUE(c.T_imu_lidar.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_EQ(c.camera.width, 752);
  EXPECT_EQ(c.camera.height, 480);
  EXPECT_DOUBLE_EQ(c.camera.fx, 458.654);
  EXPECT_DOUBLE_EQ(c.camera.fy, 457.296);
  EXPECT_DOUBLE_EQ(c.camera.cx, 367.215);
  EXPECT_DOUBLE_EQ(c.camera.cy, 248.375);
  EXPECT_EQ(c.camera.distortion, DistortionModel::kRadialTangential);
  const std::vector<double> expected{-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  EXPECT_EQ(c.camera.distortion_coeffs, expected);
  EXPECT_EQ(c.camera_time_offset, 0);
}

TEST(EurocReader, GroundTruthComesFromTheTumFileWhenTheCsvIsAbsent) {
  DROVER_REQUIRE_SHARED(kSeq);
  auto reader = openEuroc(kSeq.string(), DatasetOptions{});
  const GroundTruth& gt = reader->groundTruth();
  EXPECT_EQ(gt.body_frame, "imu");
  ASSERT_EQ(gt.poses.size(), 28712u);
  // First line: 1403715274.30214 0.878612 2.142470 0.947262 -0.828459 -0.058956 -0.553641 0.060514
  EXPECT_EQ(gt.poses.front().t, 1403715274302140000);
  EXPECT_TRUE(gt.poses.front().T_world_body.translation().isApprox(Eigen::Vector3d(0.878612, 2.142470, 0.947262)));
  const Eigen::Quaterniond q(gt.poses.front().T_world_body.linear());
  const Eigen::Quaterniond expected = Eigen::Quaterniond(0.060514, -0.828459, -0.058956, -0.553641).normalized();
  EXPECT_NEAR(std::abs(q.dot(expected)), 1.0, 1e-12);
  EXPECT_EQ(gt.poses.back().t, 1403715417857140000);
}

TEST(EurocReader, AcceptsTheMav0FolderItself) {
  DROVER_REQUIRE_SHARED(kSeq);
  DatasetOptions options;
  options.load_images = false;
  auto reader = openEuroc((kSeq / "mav0").string(), options);
  EXPECT_EQ(reader->describe(), "EuRoC V1_01_easy_micro");
  EXPECT_EQ(reader->groundTruth().poses.size(), 28712u);  // groundtruth_tum.txt beside mav0/ is still found
  EXPECT_EQ(readStream(*reader).imu.size(), 29120u);
}

// The ADIS16448's figures as the snippet's imu0/sensor.yaml gives them (read by hand).
TEST(EurocReader, TheImuNoiseFiguresAreThoseOfTheSnippetsSensorYaml) {
  DROVER_REQUIRE_SHARED(kSeq);
  const EurocImuNoise noise = readEurocImuNoise(kSeq.string());
  EXPECT_EQ(noise.gyroscope_noise_density, 1.6968e-04);
  EXPECT_EQ(noise.gyroscope_random_walk, 1.9393e-05);
  EXPECT_EQ(noise.accelerometer_noise_density, 2.0e-3);
  EXPECT_EQ(noise.accelerometer_random_walk, 3.0e-3);
}

TEST(EurocReader, HonoursLoadImuAndLoadImages) {
  DROVER_REQUIRE_SHARED(kSeq);
  DatasetOptions none;
  none.load_imu = false;
  none.load_images = false;
  auto reader = openEuroc(kSeq.string(), none);
  EXPECT_FALSE(reader->next().has_value());
  EXPECT_EQ(reader->calibration().camera.width, 752);  // calibration and ground truth are still read
}

}  // namespace
}  // namespace drover::io
