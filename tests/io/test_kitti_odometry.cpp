#include "io/kitti_odometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <fstream>
#include <sstream>

#include "io/error.hpp"
#include "io/kitti_common.hpp"
#include "io/kitti_fixture_util.hpp"
#include "support/shared_data.hpp"
#include "support/expect_io_error.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using test::writeText;

using test::expectIoError;

// The first `n` numbers after "key:" in a KITTI calib file, parsed independently of the reader.
std::vector<double> calibValues(const fs::path& file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key + ":", 0) != 0) continue;
    std::istringstream ss(line.substr(key.size() + 1));
    std::vector<double> v;
    double x;
    while (ss >> x) v.push_back(x);
    return v;
  }
  return {};
}

Eigen::Matrix4d rowMajor34(const std::vector<double>& v) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  for (int i = 0; i < 12; ++i) M(i / 4, i % 4) = v[i];
  return M;
}

// ---- Real data: sequences 00 and 05 (10 frames each) ----

struct SequenceFacts {
  std::string name;
  int width, height;
};

class KittiOdometryRealData : public ::testing::TestWithParam<SequenceFacts> {};

TEST_P(KittiOdometryRealData, YieldsScansAndImagesInTimeOrderWithExactPoints) {
  const auto seq = test::sharedData("kitti/sequences/" + GetParam().name);
  DROVER_REQUIRE_SHARED(seq);
  KittiOdometryReader reader(seq.string(), DatasetOptions{});
  EXPECT_NE(reader.describe().find("KITTI odometry " + GetParam().name), std::string::npos);
  Time last = -1;
  for (int frame = 0; frame < 10; ++frame) {
    auto m1 = reader.next();
    ASSERT_TRUE(m1 && std::holds_alternative<LidarScan>(*m1)) << "frame " << frame << ": scan first";
    const auto& scan = std::get<LidarScan>(*m1);
    char name[16];
    std::snprintf(name, sizeof(name), "%06d", frame);
    const fs::path bin = seq / "velodyne" / (std::string(name) + ".bin");
    ASSERT_EQ(scan.points.size(), fs::file_size(bin) / 16);
    EXPECT_GT(scan.points.size(), 100000u);
    float first[4];
    std::ifstream(bin, std::ios::binary).read(reinterpret_cast<char*>(first), sizeof(first));
    EXPECT_EQ(scan.points[0].x, first[0]);
    EXPECT_EQ(scan.points[0].y, first[1]);
    EXPECT_EQ(scan.points[0].z, first[2]);
    EXPECT_EQ(scan.points[0].intensity, first[3]);
    EXPECT_FALSE(scan.has_time);
    EXPECT_FALSE(scan.has_ring);
    EXPECT_EQ(scan.t, scan.t_end);
    EXPECT_EQ(scan.t, reader.frameTimes()[frame]);
    EXPECT_GT(scan.t, last);
    auto m2 = reader.next();
    ASSERT_TRUE(m2 && std::holds_alternative<CameraFrame>(*m2)) << "frame " << frame << ": then the image";
    const auto& cam = std::get<CameraFrame>(*m2);
    EXPECT_EQ(cam.t, scan.t);
    EXPECT_EQ(cam.camera_id, 2);
    EXPECT_EQ(cam.image.width, GetParam().width);
    EXPECT_EQ(cam.image.height, GetParam().height);
    EXPECT_EQ(cam.image.channels, 3);
    EXPECT_EQ(cam.image.data.size(), static_cast<std::size_t>(GetParam().width * GetParam().height * 3));
    last = cam.t;
  }
  // times.txt lists the full sequence; only 10 frames are shared, so frame 10 must fail by name.
  expectIoError([&] { reader.next(); }, {"000010.bin", "frame 10", "missing"});
}

TEST_P(KittiOdometryRealData, CalibrationFollowsCalibTxt) {
  const auto seq = test::sharedData("kitti/sequences/" + GetParam().name);
  DROVER_REQUIRE_SHARED(seq);
  KittiOdometryReader reader(seq.string(), DatasetOptions{});
  const auto P2 = calibValues(seq / "calib.txt", "P2");
  const Calibration& c = reader.calibration();
  EXPECT_EQ(c.camera.fx, P2[0]);
  EXPECT_EQ(c.camera.fy, P2[5]);
  EXPECT_EQ(c.camera.cx, P2[2]);
  EXPECT_EQ(c.camera.cy, P2[6]);
  EXPECT_EQ(c.camera.width, GetParam().width);
  EXPECT_EQ(c.camera.height, GetParam().height);
  EXPECT_TRUE(c.T_imu_lidar.isApprox(Eigen::Isometry3d::Identity()));
  // Camera 2's centre in the camera-0 frame is -K^-1 p4; KITTI's rig puts it ~6 cm left (-x) of camera 0.
  const double tz = P2[11], tx = (P2[3] - P2[2] * tz) / P2[0], ty = (P2[7] - P2[6] * tz) / P2[5];
  const Eigen::Matrix4d Tr = rowMajor34(calibValues(seq / "calib.txt", "Tr"));
  const Eigen::Vector4d centre_lidar = Tr.inverse() * Eigen::Vector4d(-tx, -ty, -tz, 1);
  EXPECT_NEAR(tx, 0.06, 0.005);
  EXPECT_LT((c.T_imu_cam.translation() - centre_lidar.head<3>()).norm(), 1e-6);
  EXPECT_LT((c.T_imu_cam.linear() - Tr.inverse().topLeftCorner<3, 3>()).cwiseAbs().maxCoeff(), 1e-6);
}

TEST_P(KittiOdometryRealData, GroundTruthInLidarFrameIsTrInverseTimesCameraPoseTimesTr) {
  const auto seq = test::sharedData("kitti/sequences/" + GetParam().name);
  DROVER_REQUIRE_SHARED(seq);
  KittiOdometryReader reader(seq.string(), DatasetOptions{});
  const GroundTruth& gt = reader.groundTruth();
  EXPECT_EQ(gt.body_frame, "lidar");
  ASSERT_EQ(gt.poses.size(), reader.frameTimes().size());
  ASSERT_EQ(reader.groundTruthCam0().size(), gt.poses.size());
  EXPECT_LT((reader.groundTruthCam0()[0].T_world_body.matrix() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(),
            1e-6);
  EXPECT_LT((gt.poses[0].T_world_body.matrix() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(), 1e-6);
  // Line 101 of poses.txt (frame 100), converted by hand with a general 4x4 inverse.
  std::ifstream in(seq / "poses.txt");
  std::string line;
  for (int i = 0; i <= 100; ++i) std::getline(in, line);
  std::istringstream ss(line);
  std::vector<double> v(12);
  for (auto& x : v) ss >> x;
  const Eigen::Matrix4d Tr = rowMajor34(calibValues(seq / "calib.txt", "Tr"));
  const Eigen::Matrix4d expected = Tr.inverse() * rowMajor34(v) * Tr;
  EXPECT_LT((gt.poses[100].T_world_body.matrix() - expected).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_EQ(gt.poses[100].t, reader.frameTimes()[100]);
}

INSTANTIATE_TEST_SUITE_P(Shared, KittiOdometryRealData,
                         ::testing::Values(SequenceFacts{"00", 1241, 376}, SequenceFacts{"05", 1226, 370}),
                         [](const auto& info) { return "seq" + info.param.name; });

TEST(KittiOdometryReader, MissingChosenImageFolderIsAnErrorAtOpen) {
  const auto seq = test::sharedData("kitti/sequences/00");
  DROVER_REQUIRE_SHARED(seq);
  DatasetOptions options;
  options.kitti_camera = 0;  // image_0 is not shared
  expectIoError([&] { KittiOdometryReader(seq.string(), options); }, {"image_0", "image folder missing"});
  options.kitti_camera = 1;
  EXPECT_THROW(KittiOdometryReader(seq.string(), options), std::invalid_argument);
}

// ---- Fixtures ----

// Tr: lidar x (forward) -> camera z, lidar y (left) -> camera -x, lidar z (up) -> camera -y; t = (0.1, -0.2, 0.3).
const char* kCalib =
    "P0: 700 0 600 0 0 700 180 0 0 0 1 0\n"
    "P1: 700 0 600 -380 0 700 180 0 0 0 1 0\n"
    "P2: 700 0 600 42 0 700 180 0.7 0 0 1 0.002\n"
    "P3: 700 0 600 -330 0 700 180 2 0 0 1 0.005\n"
    "Tr: 0 -1 0 0.1 0 0 -1 -0.2 1 0 0 0.3\n";

// A two-frame sequence, grey camera 0 and colour camera 2, no ground truth.
fs::path writeSequence(const TempDir& dir) {
  const fs::path seq = dir / "sequences" / "11";
  writeText(seq / "times.txt", "0.000000e+00\n1.000000e-01\n");
  writeText(seq / "calib.txt", kCalib);
  test::writeBin(seq / "velodyne" / "000000.bin", {{1, 2, 3, 0.5f}, {4, 5, 6, 0.25f}});
  test::writeBin(seq / "velodyne" / "000001.bin", {{7, 8, 9, 1}});
  for (const char* f : {"000000.png", "000001.png"}) {
    test::writePng(seq / "image_0" / f, 3, 2, 1, {0, 1, 2, 3, 4, 5});
    test::writePng(seq / "image_2" / f, 2, 1, 3, {10, 20, 30, 40, 50, 60});  // RGB
  }
  return seq;
}

TEST(KittiOdometryReader, ReadsFixtureGreyAndColourImagesAsMonoAndBgr) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  DatasetOptions options;
  options.kitti_camera = 0;
  KittiOdometryReader grey(seq.string(), options);
  EXPECT_TRUE(grey.groundTruth().poses.empty());  // sequence without poses.txt: no ground truth, no error
  const auto scan = std::get<LidarScan>(*grey.next());
  ASSERT_EQ(scan.points.size(), 2u);
  EXPECT_EQ(scan.points[1].y, 5.0f);
  EXPECT_EQ(scan.points[1].intensity, 0.25f);
  const auto img = std::get<CameraFrame>(*grey.next());
  EXPECT_EQ(img.camera_id, 0);
  EXPECT_EQ(img.image.channels, 1);
  EXPECT_EQ(img.image.data, (std::vector<std::uint8_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(grey.calibration().camera.width, 3);
  EXPECT_TRUE(grey.calibration().T_imu_cam.isApprox(Eigen::Isometry3d(grey.T_cam0_lidar().inverse())));
  std::get<LidarScan>(*grey.next());
  EXPECT_EQ(std::get<CameraFrame>(*grey.next()).t, 100'000'000);
  EXPECT_FALSE(grey.next().has_value());

  options.kitti_camera = 2;
  KittiOdometryReader colour(seq.string(), options);
  colour.next();
  const auto bgr = std::get<CameraFrame>(*colour.next());
  EXPECT_EQ(bgr.image.channels, 3);
  EXPECT_EQ(bgr.image.data, (std::vector<std::uint8_t>{30, 20, 10, 60, 50, 40}));
}

TEST(KittiOdometryReader, CameraTwoExtrinsicsMatchHandComputation) {
  TempDir dir;
  KittiOdometryReader reader(writeSequence(dir).string(), DatasetOptions{});
  // K^-1 p4 = ((42 - 600*0.002)/700, (0.7 - 180*0.002)/700, 0.002); centre in cam0 = -that; in lidar
  // p_l = R_lc (p_c - t): x_l = z_c', y_l = -x_c', z_l = -y_c' with p_c' = p_c - (0.1, -0.2, 0.3).
  const double tx = 40.8 / 700, ty = 0.34 / 700, tz = 0.002;
  const Eigen::Vector3d expected(-tz - 0.3, tx + 0.1, ty - 0.2);
  EXPECT_LT((reader.calibration().T_imu_cam.translation() - expected).norm(), 1e-12);
  EXPECT_EQ(reader.calibration().camera.fx, 700);
  EXPECT_EQ(reader.calibration().camera.cy, 180);
}

TEST(KittiOdometryReader, GroundTruthTurnsCameraYawIntoLidarYaw) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  // Frame 1: rotation by th about camera y (down), i.e. turning right, and 5 m forward, 1 m right.
  const double th = 0.5, c = std::cos(th), s = std::sin(th);
  std::ostringstream poses;
  poses.precision(17);
  poses << "1 0 0 0 0 1 0 0 0 0 1 0\n" << c << " 0 " << s << " 1 0 1 0 0 " << -s << " 0 " << c << " 5\n";
  writeText(seq / "poses.txt", poses.str());
  KittiOdometryReader reader(seq.string(), DatasetOptions{});
  const auto& T = reader.groundTruth().poses.at(1).T_world_body;
  // Turning right is yaw -th about lidar z (up).
  EXPECT_LT((T.linear() - Eigen::AngleAxisd(-th, Eigen::Vector3d::UnitZ()).toRotationMatrix()).norm(), 1e-12);
  // t_l = R_lc (R_c t_cl + t_c - t_cl), t_cl = (0.1, -0.2, 0.3), t_c = (1, 0, 5).
  const Eigen::Vector3d a(c * 0.1 + s * 0.3 + 1 - 0.1, -0.2 + 0 + 0.2, -s * 0.1 + c * 0.3 + 5 - 0.3);
  EXPECT_LT((T.translation() - Eigen::Vector3d(a.z(), -a.x(), -a.y())).norm(), 1e-12);
}

TEST(KittiOdometryReader, RejectsBinWhoseSizeIsNotAMultipleOf16) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  writeText(seq / "velodyne" / "000000.bin", std::string(20, '\0'));
  KittiOdometryReader reader(seq.string(), DatasetOptions{});
  expectIoError([&] { reader.next(); }, {"000000.bin", "not a multiple of 16"});
}

TEST(KittiOdometryReader, DropsPointsWithANanOrInfValueAndCountsThemInTheScan) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  const float inf = std::numeric_limits<float>::infinity();
  test::writeBin(seq / "velodyne" / "000001.bin",
                 {{1, 2, 3, 0}, {1, std::nanf(""), 3, 0}, {4, 5, 6, inf}, {7, 8, 9, 0.5f}});
  KittiOdometryReader reader(seq.string(), DatasetOptions{});
  reader.next(), reader.next();
  const auto scan = std::get<LidarScan>(*reader.next());
  ASSERT_EQ(scan.points.size(), 2u);
  EXPECT_EQ(scan.points[1].x, 7.0f);
  EXPECT_EQ(scan.points[1].intensity, 0.5f);
  EXPECT_EQ(scan.dropped_nonfinite, 2u);
  EXPECT_EQ(reader.drops().measurements, 0u);
}

TEST(KittiOdometryReader, MissingScanOrImageOfAListedFrameFailsWhenReadNamingTheFrame) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  fs::remove(seq / "image_2" / "000001.png");
  fs::remove(seq / "velodyne" / "000000.bin");
  KittiOdometryReader reader(seq.string(), DatasetOptions{});
  expectIoError([&] { reader.next(); }, {"000000.bin", "frame 0", "missing"});
  DatasetOptions no_lidar;
  no_lidar.load_lidar = false;
  KittiOdometryReader images(seq.string(), no_lidar);
  EXPECT_EQ(std::get<CameraFrame>(*images.next()).t, 0);
  expectIoError([&] { images.next(); }, {"000001.png", "frame 1", "missing"});
}

TEST(KittiOdometryReader, RejectsUndecodableImage) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  writeText(seq / "image_2" / "000000.png", "not a png");
  DatasetOptions options;
  options.load_lidar = false;
  KittiOdometryReader reader(seq.string(), options);
  expectIoError([&] { reader.next(); }, {"000000.png", "cannot decode"});
}

TEST(KittiOdometryReader, RejectsCalibMissingAKeyNamingIt) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  std::string calib = kCalib;
  writeText(seq / "calib.txt", calib.substr(0, calib.find("Tr:")));
  expectIoError([&] { KittiOdometryReader(seq.string(), DatasetOptions{}); }, {"calib.txt", "missing key 'Tr'"});
  writeText(seq / "calib.txt", "P0: 1 2 3\n");
  expectIoError([&] { KittiOdometryReader(seq.string(), DatasetOptions{}); }, {"'P0' has 3 values, expected 12"});
}

TEST(KittiOdometryReader, RejectsNonOrthonormalTr) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  std::string calib = kCalib;
  writeText(seq / "calib.txt", calib.substr(0, calib.find("Tr:")) + "Tr: 0 -1 0 0 0 0 -1 0 1 0 0.1 0\n");
  expectIoError([&] { KittiOdometryReader(seq.string(), DatasetOptions{}); }, {"calib.txt", "Tr", "orthonormal"});
}

TEST(KittiOdometryReader, RejectsMissingOrBackwardsTimesAndMismatchedPoses) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  writeText(seq / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
  expectIoError([&] { KittiOdometryReader(seq.string(), DatasetOptions{}); }, {"has 2 times", "has 1 poses"});
  fs::remove(seq / "poses.txt");
  writeText(seq / "times.txt", "0.2\n0.1\n");
  expectIoError([&] { KittiOdometryReader(seq.string(), DatasetOptions{}); }, {"times.txt", "line 2", "backwards"});
  fs::remove(seq / "times.txt");
  expectIoError([&] { KittiOdometryReader(seq.string(), DatasetOptions{}); }, {"times.txt", "cannot open"});
  expectIoError([&] { openKittiOdometry((dir / "nowhere").string(), DatasetOptions{}); }, {"not found"});
}

TEST(KittiOdometryReader, MalformedTrLineIsReportedAsMalformedNotMissing) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  writeText(seq / "calib.txt", std::string(kCalib).replace(std::string(kCalib).find("Tr: 0 -1"), 8, "Tr: 0 -x"));
  expectIoError([&] { KittiOdometryReader(seq.string(), DatasetOptions{}); },
                {"calib.txt", "(line 5)", "key 'Tr' has a value that is not a number: '-x'"});
}

TEST(KittiOdometryReader, ZeroFocalLengthOfTheChosenCameraIsAnErrorNamingTheKey) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  writeText(seq / "calib.txt", std::string(kCalib).replace(std::string(kCalib).find("P2: 700 0 600 42 0 700"), 22,
                                                           "P2: 0 0 600 42 0 0"));
  expectIoError([&] { KittiOdometryReader(seq.string(), DatasetOptions{}); },
                {"calib.txt", "(line 3)", "key 'P2': focal lengths must be > 0 px, got fx 0, fy 0"});
}

TEST(KittiOdometryReader, ImageOfAnotherSizeThanFrameZerosIsAnErrorNamingTheFile) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  test::writePng(seq / "image_2" / "000001.png", 1, 1, 3, {1, 2, 3});
  DatasetOptions options;
  options.load_lidar = false;
  KittiOdometryReader reader(seq.string(), options);
  reader.next();
  expectIoError([&] { reader.next(); }, {"000001.png", "(frame 1)", "image is 1x1 px, frame 0's is 2x1"});
}

TEST(KittiOdometryReader, PngHeaderClaimingAHugeImageIsRefusedBeforeDecoding) {
  TempDir dir;
  const fs::path seq = writeSequence(dir);
  // A valid 2x1 PNG whose IHDR then claims 100000 x 100000 px (the CRC no longer matches: OpenCV is never asked).
  std::string png = test::readText(seq / "image_2" / "000001.png");
  const unsigned char huge[8] = {0, 1, 0x86, 0xa0, 0, 1, 0x86, 0xa0};  // 100000 big-endian, twice
  png.replace(16, 8, reinterpret_cast<const char*>(huge), 8);
  writeText(seq / "image_2" / "000001.png", png);
  DatasetOptions options;
  options.load_lidar = false;
  KittiOdometryReader reader(seq.string(), options);
  reader.next();
  expectIoError([&] { reader.next(); }, {"000001.png", "(header)", "header claims 100000x100000 px"});
  // The largest sizes a PNG header can hold: their product must not overflow into an acceptable number.
  png.replace(16, 8, std::string(8, '\xff'));
  writeText(seq / "image_2" / "000001.png", png);
  KittiOdometryReader again(seq.string(), options);
  again.next();
  expectIoError([&] { again.next(); }, {"000001.png", "(header)", "header claims 4294967295x4294967295 px"});
}

TEST(KittiScanText, DropsLinesWithNanOrInfAndCountsThem) {
  TempDir dir;
  writeText(dir / "scan.txt", "1 2 3 0.5\nnan 2 3 0.5\n4 5 6 -inf\n7 8 9 1e300\n10 11 12 0\n");
  const LidarScan scan = readKittiScanText((dir / "scan.txt").string(), 0, 0);
  ASSERT_EQ(scan.points.size(), 2u);
  EXPECT_EQ(scan.points[1].x, 10.0f);
  EXPECT_EQ(scan.dropped_nonfinite, 3u);
  writeText(dir / "scan.txt", "1 2 3 0.5\n1 2 x 0.5\n");
  expectIoError([&] { readKittiScanText((dir / "scan.txt").string(), 0, 0); }, {"scan.txt", "line 2"});
}

}  // namespace
}  // namespace drover::io
