#include "io/kitti_raw.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "io/error.hpp"
#include "io/kitti_fixture_util.hpp"
#include "io/kitti_oxts.hpp"
#include "support/expect_io_error.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using test::writeText;

constexpr double kPi = 3.14159265358979323846;
constexpr double kEr = 6378137.0;
constexpr Time kRawT0 = 1317386421LL * kNanosPerSecond;  // 2011-09-30 12:40:21 read as UTC (timegm)

using test::expectIoError;

// The fixture's motion: a circle at 10 m/s with yaw rate 0.2 rad/s, climbing 0.5 m/s, constant roll and pitch;
// x east, y north (metres from the start), yaw from east.
struct Motion {
  static constexpr double v = 10, w = 0.2, yaw0 = 0.3, roll = 0.02, pitch = -0.01, alt0 = 110, climb = 0.5;
  static constexpr double lat0 = 49.0, lon0 = 8.4;
  static double yaw(double t) { return yaw0 + w * t; }
  static Eigen::Vector3d position(double t) {
    const double r = v / w;
    return {r * (std::sin(yaw(t)) - std::sin(yaw0)), -r * (std::cos(yaw(t)) - std::cos(yaw0)), alt0 + climb * t};
  }
  static Eigen::Matrix3d rotation(double t) {
    return (Eigen::AngleAxisd(yaw(t), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
};

// Inverse of the devkit Mercator (mx = s lon pi er / 180, my = s er log(tan((90 + lat) pi / 360))).
std::pair<double, double> latLonAt(const Eigen::Vector3d& p) {
  const double s = std::cos(Motion::lat0 * kPi / 180);
  const double mx0 = s * Motion::lon0 * kPi * kEr / 180;
  const double my0 = s * kEr * std::log(std::tan((90 + Motion::lat0) * kPi / 360));
  const double lon = (mx0 + p.x()) * 180 / (s * kPi * kEr);
  const double lat = 360 / kPi * std::atan(std::exp((my0 + p.y()) / (s * kEr))) - 90;
  return {lat, lon};
}

std::string stamp(Time offset_ns) {  // "2011-09-30 12:40:SS.fffffffff", offset from 12:40:21 (< 39 s)
  char buf[64];
  const Time ns = 21 * kNanosPerSecond + offset_ns;
  std::snprintf(buf, sizeof(buf), "2011-09-30 12:40:%02lld.%09lld", static_cast<long long>(ns / kNanosPerSecond),
                static_cast<long long>(ns % kNanosPerSecond));
  return buf;
}

std::string numbers(std::initializer_list<double> v) {
  std::ostringstream ss;
  ss.precision(17);
  for (double x : v) ss << x << ' ';
  return ss.str();
}

constexpr int kOxts = 201;                                         // 2 s at 100 Hz
const Time kScanStart[3] = {1'000'000, 101'000'000, 200'000'000};  // the last ties with oxts sample 20
const Time kImage[2] = {50'000'000, 101'000'000};                  // the last ties with scan 1's start

void writeCalib(const fs::path& date) {
  writeText(date / "calib_imu_to_velo.txt", "calib_time: 25-May-2012 16:47:16\nR: " +
                                                numbers({std::cos(0.01), -std::sin(0.01), 0, std::sin(0.01),
                                                         std::cos(0.01), 0, 0, 0, 1}) +
                                                "\nT: -0.81 0.32 -0.8\n");
  writeText(date / "calib_velo_to_cam.txt",
            "calib_time: 15-Mar-2012 11:37:16\nR: 0 -1 0 0 0 -1 1 0 0\nT: -0.004 -0.076 -0.27\n"
            "delta_f: 0 0\ndelta_c: 0 0\n");
  const double c = std::cos(0.01), s = std::sin(0.01), c2 = std::cos(0.005), s2 = std::sin(0.005);
  writeText(date / "calib_cam_to_cam.txt",
            "calib_time: 09-Jan-2012 13:57:47\ncorner_dist: 9.950000e-02\n"
            "S_00: 1392 512\nK_00: 984.2 0 690 0 980.8 233.2 0 0 1\nD_00: -0.37 0.2 0.0022 0.0014 -0.072\n"
            "R_00: 1 0 0 0 1 0 0 0 1\nT_00: 0 0 0\nS_rect_00: 1242 375\nR_rect_00: " +
                numbers({1, 0, 0, 0, c, -s, 0, s, c}) +
                "\nP_rect_00: 721.5 0 609.6 0 0 721.5 172.9 0 0 0 1 0\n"
                "S_02: 1392 512\nK_02: 959.8 0 696 0 956.9 224.2 0 0 1\nD_02: -0.37 0.2 0.0009 -0.0008 -0.073\n"
                "R_02: " +
                numbers({c2, 0, s2, 0, 1, 0, -s2, 0, c2}) +
                "\nT_02: 0.0599 -0.0013 0.0057\nS_rect_02: 1242 375\n"
                "P_rect_02: 721.5 0 609.6 44.86 0 721.5 172.9 0.2164 0 0 1 0.002746\n");
}

// A raw drive of the given layout under dir/2011_09_30/; returns the drive folder.
fs::path writeDrive(const TempDir& dir, bool sync) {
  const fs::path date = dir / "2011_09_30";
  const fs::path drive = date / (sync ? "2011_09_30_drive_0018_sync" : "2011_09_30_drive_0018_extract");
  writeCalib(date);
  std::string oxts_stamps;
  for (int k = 0; k < kOxts; ++k) {
    const double t = 0.01 * k;
    const auto [lat, lon] = latLonAt(Motion::position(t));
    const double vf = Motion::v, al = Motion::v * Motion::w;
    char name[32];
    std::snprintf(name, sizeof(name), "%010d.txt", k);
    writeText(drive / "oxts" / "data" / name,
              numbers({lat, lon, Motion::position(t).z(), Motion::roll, Motion::pitch, Motion::yaw(t), 1, 2, vf, 0,
                       Motion::climb, 21, 22, 23, 0.1, al, 9.81, 11, 12, 13, 0.001, -0.002, Motion::w, 0.05, 0.02, 4,
                       9, 5, 5, 6}) +
                  "\n");
    oxts_stamps += stamp(10'000'000LL * k) + "\n";
  }
  writeText(drive / "oxts" / "timestamps.txt", oxts_stamps);
  std::string start, end, mid;
  for (int i = 0; i < 3; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%010d.%s", i, sync ? "bin" : "txt");
    const fs::path scan = drive / "velodyne_points" / "data" / name;
    if (sync)
      test::writeBin(scan, {{1.5f * i, 2, 3, 0.5f}, {4, 5, 6, 0.25f}});
    else
      writeText(scan, numbers({1.5 * i, 2, 3, 0.5}) + "\n4 5 6 0.25\n");
    start += stamp(kScanStart[i]) + "\n";
    end += stamp(kScanStart[i] + 98'000'000) + "\n";
    mid += stamp(kScanStart[i] + 50'000'000) + "\n";
  }
  writeText(drive / "velodyne_points" / "timestamps_start.txt", start);
  writeText(drive / "velodyne_points" / "timestamps_end.txt", end);
  writeText(drive / "velodyne_points" / "timestamps.txt", mid);
  for (const char* cam : {"image_00", "image_02"}) {
    std::string stamps;
    for (int i = 0; i < 2; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "%010d.png", i);
      if (std::string(cam) == "image_00")
        test::writePng(drive / cam / "data" / name, 2, 1, 1, {7, 8});
      else
        test::writePng(drive / cam / "data" / name, 1, 1, 3, {1, 2, 3});
      stamps += stamp(kImage[i]) + "\n";
    }
    writeText(drive / cam / "timestamps.txt", stamps);
  }
  return drive;
}

class KittiRawLayouts : public ::testing::TestWithParam<bool> {};  // true = sync, false = extract

TEST_P(KittiRawLayouts, GroundTruthReproducesTheAnalyticCircleToAMillimetre) {
  TempDir dir;
  KittiRawReader reader(writeDrive(dir, GetParam()).string(), DatasetOptions{});
  EXPECT_EQ(reader.isSync(), GetParam());
  const GroundTruth& gt = reader.groundTruth();
  EXPECT_EQ(gt.body_frame, "imu");
  ASSERT_EQ(gt.poses.size(), static_cast<std::size_t>(kOxts));
  const Eigen::Matrix3d R0 = Motion::rotation(0);
  double worst = 0;
  for (int k = 0; k < kOxts; ++k) {
    const double t = 0.01 * k;
    EXPECT_EQ(gt.poses[k].t, kRawT0 + 10'000'000LL * k);
    const Eigen::Vector3d expected = R0.transpose() * (Motion::position(t) - Motion::position(0));
    worst = std::max(worst, (gt.poses[k].T_world_body.translation() - expected).norm());
    EXPECT_LT((gt.poses[k].T_world_body.linear() - R0.transpose() * Motion::rotation(t)).norm(), 1e-9);
  }
  EXPECT_LT(worst, 1e-3);
  // 2 s on the circle: chord 2 r sin(w T / 2) with r = 50 m.
  EXPECT_NEAR(gt.poses.back().T_world_body.translation().head<2>().norm(), 100 * std::sin(0.2), 0.06);
}

TEST_P(KittiRawLayouts, ImuSamplesUseForwardLeftUpFields) {
  TempDir dir;
  KittiRawReader reader(writeDrive(dir, GetParam()).string(), DatasetOptions{});
  ASSERT_EQ(reader.imuSamples().size(), static_cast<std::size_t>(kOxts));
  const ImuSample& s = reader.imuSamples()[7];
  EXPECT_EQ(s.t, kRawT0 + 70'000'000);
  EXPECT_EQ(s.omega_imu, Eigen::Vector3d(0.001, -0.002, 0.2));  // wf wl wu, not wx wy wz = 11 12 13
  EXPECT_EQ(s.acc_imu, Eigen::Vector3d(0.1, 2.0, 9.81));         // af al au, not ax ay az = 21 22 23
  ASSERT_TRUE(s.q_world_imu.has_value());
  EXPECT_LT((s.q_world_imu->toRotationMatrix() - Motion::rotation(0.07)).norm(), 1e-12);
}

TEST_P(KittiRawLayouts, MergesStreamsInTimeOrderImuBeforeLidarBeforeCamera) {
  TempDir dir;
  KittiRawReader reader(writeDrive(dir, GetParam()).string(), DatasetOptions{});
  std::vector<Measurement> all;
  while (auto m = reader.next()) all.push_back(std::move(*m));
  ASSERT_EQ(all.size(), static_cast<std::size_t>(kOxts + 3 + 2));
  int scans = 0, images = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (i > 0) {
      EXPECT_LE(measurementTime(all[i - 1]), measurementTime(all[i]));
    }
    if (const auto* scan = std::get_if<LidarScan>(&all[i])) {
      EXPECT_EQ(scan->t, kRawT0 + kScanStart[scans]);
      EXPECT_EQ(scan->t_end, kRawT0 + kScanStart[scans] + 98'000'000);
      EXPECT_FALSE(scan->has_time);
      ASSERT_EQ(scan->points.size(), 2u);
      EXPECT_EQ(scan->points[0].x, 1.5f * scans);
      EXPECT_EQ(scan->points[1].intensity, 0.25f);
      if (scans == 1) {
        EXPECT_TRUE(std::holds_alternative<CameraFrame>(all[i + 1]));  // tie at 0.101 s: lidar first
      }
      if (scans == 2) {
        EXPECT_TRUE(std::holds_alternative<ImuSample>(all[i - 1]));  // tie at 0.200 s: IMU first
      }
      ++scans;
    } else if (const auto* cam = std::get_if<CameraFrame>(&all[i])) {
      EXPECT_EQ(cam->t, kRawT0 + kImage[images]);
      EXPECT_EQ(cam->camera_id, 2);
      EXPECT_EQ(cam->image.data, (std::vector<std::uint8_t>{3, 2, 1}));  // RGB file -> BGR
      ++images;
    }
  }
  EXPECT_EQ(scans, 3);
  EXPECT_EQ(images, 2);
}

// The devkit projects velodyne points with P_rect_0x * R_rect_00 * T_cam0_velo (sync, rectified) or
// K_0x * [R_0x | T_0x] * T_cam0_velo (extract, unrectified, before distortion); our calibration must agree.
TEST_P(KittiRawLayouts, CalibrationProjectsLidarPointsLikeTheDevkit) {
  TempDir dir;
  KittiRawReader reader(writeDrive(dir, GetParam()).string(), DatasetOptions{});
  const Calibration& c = reader.calibration();
  Eigen::Matrix4d T_cam0_velo = Eigen::Matrix4d::Identity();
  T_cam0_velo.topRows<3>() << 0, -1, 0, -0.004, 0, 0, -1, -0.076, 1, 0, 0, -0.27;
  const Eigen::Vector4d X(10, 2, 1, 1);
  Eigen::Vector3d y;
  if (GetParam()) {
    Eigen::Matrix4d R_rect = Eigen::Matrix4d::Identity();
    R_rect.block<3, 3>(0, 0) = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitX()).toRotationMatrix();
    Eigen::Matrix<double, 3, 4> P;
    P << 721.5, 0, 609.6, 44.86, 0, 721.5, 172.9, 0.2164, 0, 0, 1, 0.002746;
    y = P * R_rect * T_cam0_velo * X;
    EXPECT_EQ(c.camera.distortion, DistortionModel::kNone);
    EXPECT_EQ(c.camera.width, 1242);
  } else {
    Eigen::Matrix<double, 3, 4> Rt;
    Rt.leftCols<3>() = Eigen::AngleAxisd(0.005, Eigen::Vector3d::UnitY()).toRotationMatrix();
    Rt.col(3) << 0.0599, -0.0013, 0.0057;
    Eigen::Matrix3d K;
    K << 959.8, 0, 696, 0, 956.9, 224.2, 0, 0, 1;
    y = K * Rt * T_cam0_velo * X;
    EXPECT_EQ(c.camera.distortion, DistortionModel::kRadialTangential);
    EXPECT_EQ(c.camera.distortion_coeffs, (std::vector<double>{-0.37, 0.2, 0.0009, -0.0008, -0.073}));
    EXPECT_EQ(c.camera.width, 1392);
  }
  const Eigen::Vector3d p_cam = c.T_imu_cam.inverse() * c.T_imu_lidar * X.head<3>();
  EXPECT_NEAR(c.camera.fx * p_cam.x() / p_cam.z() + c.camera.cx, y.x() / y.z(), 1e-9);
  EXPECT_NEAR(c.camera.fy * p_cam.y() / p_cam.z() + c.camera.cy, y.y() / y.z(), 1e-9);
  // T_imu_lidar = inv(T_velo_imu), T_velo_imu = [Rz(0.01) | (-0.81, 0.32, -0.8)].
  EXPECT_LT((c.T_imu_lidar.inverse().translation() - Eigen::Vector3d(-0.81, 0.32, -0.8)).norm(), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Layouts, KittiRawLayouts, ::testing::Bool(),
                         [](const auto& info) { return info.param ? "sync" : "extract"; });

TEST(KittiRawReader, ParsesTimestampsExactlyToTheNanosecond) {
  EXPECT_EQ(parseKittiTimestamp("2011-09-30 12:40:21.123456789", "f", ""), kRawT0 + 123'456'789);
  EXPECT_EQ(parseKittiTimestamp("2011-09-30 12:40:21.5", "f", ""), kRawT0 + 500'000'000);
  EXPECT_EQ(parseKittiTimestamp("2011-09-30 12:40:21", "f", ""), kRawT0);
  EXPECT_EQ(parseKittiTimestamp("1970-01-01 00:00:00.000000001", "f", ""), 1);
  EXPECT_EQ(parseKittiTimestamp("2012-03-01 00:00:00", "f", ""), 1330560000LL * kNanosPerSecond);  // after Feb 29
  for (const char* bad : {"2011-13-30 12:40:21.1", "2011-09-30T12:40:21.1", "2011-09-30 12:40:21.", "garbage",
                          "2011-09-30 12:40:21.1234567890", "2011-09-30 12:40:2x.1"})
    EXPECT_THROW(parseKittiTimestamp(bad, "f", "line 1"), IoError) << bad;
}

TEST(KittiRawReader, RejectsCalibMissingAKey) {
  TempDir dir;
  const fs::path drive = writeDrive(dir, true);
  writeText(drive.parent_path() / "calib_imu_to_velo.txt", "R: 1 0 0 0 1 0 0 0 1\n");
  expectIoError([&] { KittiRawReader(drive.string(), DatasetOptions{}); },
                {"calib_imu_to_velo.txt", "missing key 'T'"});
  fs::remove(drive.parent_path() / "calib_cam_to_cam.txt");
  writeText(drive.parent_path() / "calib_imu_to_velo.txt", "R: 1 0 0 0 1 0 0 0 1\nT: 0 0 0\n");
  expectIoError([&] { KittiRawReader(drive.string(), DatasetOptions{}); }, {"calib_cam_to_cam.txt", "not found"});
}

TEST(KittiRawReader, CalibInTheDriveFolderWinsOverTheParent) {
  TempDir dir;
  const fs::path drive = writeDrive(dir, true);
  writeText(drive / "calib_imu_to_velo.txt", "R: 1 0 0 0 1 0 0 0 1\nT: 1 2 3\n");
  KittiRawReader reader(drive.string(), DatasetOptions{});
  EXPECT_LT((reader.calibration().T_imu_lidar.translation() - Eigen::Vector3d(-1, -2, -3)).norm(), 1e-12);
}

TEST(KittiRawReader, RejectsOxtsLineWith29Fields) {
  TempDir dir;
  const fs::path drive = writeDrive(dir, true);
  writeText(drive / "oxts" / "data" / "0000000005.txt", numbers({49, 8.4, 110, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10,
                                                                  11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23}));
  expectIoError([&] { KittiRawReader(drive.string(), DatasetOptions{}); },
                {"0000000005.txt", "line 1", "expected 30 columns, found 29"});
}

TEST(KittiRawReader, RejectsUnparsableTimestampNamingTheLine) {
  TempDir dir;
  const fs::path drive = writeDrive(dir, false);
  std::string stamps = test::readText(drive / "oxts" / "timestamps.txt");
  stamps.replace(stamps.find("12:40:21.020"), 12, "12:40:2x.020");
  writeText(drive / "oxts" / "timestamps.txt", stamps);
  expectIoError([&] { KittiRawReader(drive.string(), DatasetOptions{}); },
                {"oxts/timestamps.txt", "line 3", "unparsable timestamp"});
}

TEST(KittiRawReader, DropsAScanWhoseStampGoesBackwardsWithACountedWarning) {
  TempDir dir;
  const fs::path drive = writeDrive(dir, true);
  writeText(drive / "velodyne_points" / "timestamps_start.txt",
            stamp(kScanStart[0]) + "\n" + stamp(0) + "\n" + stamp(kScanStart[2]) + "\n");
  DatasetOptions options;
  options.load_imu = options.load_images = false;
  KittiRawReader reader(drive.string(), options);
  std::vector<Time> scans;
  while (auto m = reader.next()) scans.push_back(std::get<LidarScan>(*m).t);
  EXPECT_EQ(scans, (std::vector<Time>{kRawT0 + kScanStart[0], kRawT0 + kScanStart[2]}));
  ASSERT_EQ(reader.drops().measurements, 1u);
  const std::string& notice = reader.drops().notices.at(0);
  EXPECT_NE(notice.find("timestamps_start.txt (frame 1): dropped: timestamp goes back"), std::string::npos) << notice;
}

TEST(KittiRawReader, RejectsCountMismatchBetweenTimestampsAndDataFiles) {
  TempDir dir;
  const fs::path drive = writeDrive(dir, false);
  fs::remove(drive / "image_02" / "data" / "0000000001.png");
  expectIoError([&] { KittiRawReader(drive.string(), DatasetOptions{}); },
                {"image_02/timestamps.txt", "has 2 timestamps", "has 1 .png files"});
  fs::remove(drive / "oxts" / "data" / "0000000200.txt");
  DatasetOptions no_images;
  no_images.load_images = false;
  expectIoError([&] { KittiRawReader(drive.string(), no_images); }, {"oxts/timestamps.txt", "has 201 timestamps"});
}

TEST(KittiRawReader, WithoutOxtsAndImuThereIsNoGroundTruthButScansStillRead) {
  TempDir dir;
  const fs::path drive = writeDrive(dir, true);
  fs::remove_all(drive / "oxts");
  expectIoError([&] { KittiRawReader(drive.string(), DatasetOptions{}); }, {"oxts folder missing"});
  DatasetOptions options;
  options.load_imu = false;
  options.kitti_camera = 0;
  const auto reader = openKittiRaw(drive.string(), options);
  EXPECT_TRUE(reader->groundTruth().poses.empty());
  EXPECT_NE(reader->describe().find("KITTI raw 2011_09_30_drive_0018_sync (sync"), std::string::npos);
  EXPECT_TRUE(std::holds_alternative<LidarScan>(*reader->next()));
  const auto frame = std::get<CameraFrame>(*reader->next());
  EXPECT_EQ(frame.camera_id, 0);
  EXPECT_EQ(frame.image.channels, 1);
  EXPECT_EQ(frame.image.data, (std::vector<std::uint8_t>{7, 8}));
}

}  // namespace
}  // namespace drover::io
