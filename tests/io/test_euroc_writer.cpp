// The EuRoC writer (drover sim --format euroc): what it writes, io/euroc_reader.hpp reads back exactly, in the
// ASL layout of the real sequences; lidar scans and out-of-order records are refused, and only an earlier output
// of the writer is ever replaced.
#include <gtest/gtest.h>

#include <filesystem>

#include "io/error.hpp"
#include "io/euroc_reader.hpp"
#include "io/euroc_writer.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;
using test::TempDir;

constexpr int kEurocWidth = 10, kEurocHeight = 8;

SimDatasetDescription eurocDescription() {
  SimDatasetDescription d;
  d.calibration.T_imu_cam.linear() = Eigen::AngleAxisd(1.5, Eigen::Vector3d(1, -2, 3).normalized()).toRotationMatrix();
  d.calibration.T_imu_cam.translation() = Eigen::Vector3d(-0.0216, -0.0647, 0.0098);
  CameraIntrinsics& k = d.calibration.camera;
  k.width = kEurocWidth, k.height = kEurocHeight, k.fx = 4.58654, k.fy = 4.57296, k.cx = 3.67215, k.cy = 2.48375;
  k.distortion = DistortionModel::kRadialTangential;
  k.distortion_coeffs = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  d.sensors.camera_rate_hz = 20;
  d.sensors.gyro_noise_density = 1.6968e-04;
  d.scenario.name = "hand-made";
  return d;
}

ImuSample eurocImuAt(Time t) {
  ImuSample s;
  s.t = t;
  s.omega_imu = Eigen::Vector3d(-0.002 + 1e-12 * static_cast<double>(t), 1.0 / 3.0, 0.078);
  s.acc_imu = Eigen::Vector3d(9.81, std::sqrt(2.0), -1.4e-300);
  return s;
}

CameraFrame eurocFrameAt(Time t) {
  CameraFrame f;
  f.t = t;
  f.image.width = kEurocWidth, f.image.height = kEurocHeight, f.image.channels = 1;
  for (int i = 0; i < kEurocWidth * kEurocHeight; ++i) f.image.data.push_back(static_cast<std::uint8_t>(i * 3 + t % 11));
  return f;
}

EurocTruthState truthAt(Time t) {
  EurocTruthState s;
  s.t = t;
  s.T_world_imu.linear() = Eigen::AngleAxisd(0.001 * static_cast<double>(t), Eigen::Vector3d(0, 1, 1).normalized())
                               .toRotationMatrix();
  s.T_world_imu.translation() = Eigen::Vector3d(1.0 / 7.0, -2.5, 1.5);
  s.v_world = Eigen::Vector3d(0.5, 0, -0.1);
  s.gyro_bias = Eigen::Vector3d(-0.002, 0.019, 0.078);
  return s;
}

// IMU every 5 ns from 1000, frames every 50 ns from 1003, the truth on the IMU's stamps.
void writeEurocDataset(const fs::path& dir) {
  EurocDatasetWriter w(dir.string(), eurocDescription(), false);
  std::vector<EurocTruthState> truth;
  for (Time t = 1000; t <= 1200; t += 5) {
    w.add(eurocImuAt(t));
    truth.push_back(truthAt(t));
    if ((t - 1000) % 50 == 0 && t + 3 <= 1200) w.add(eurocFrameAt(t + 3));
  }
  w.finish(truth);
}

TEST(EurocWriter, WhatItWritesTheEurocReaderReadsBackExactly) {
  TempDir tmp;
  writeEurocDataset(tmp / "seq");
  ASSERT_TRUE(fs::is_regular_file(tmp / "seq" / "mav0" / "cam0" / "data" / "1003.png"));
  auto reader = openEuroc((tmp / "seq").string(), DatasetOptions{});
  const Calibration& c = reader->calibration();
  EXPECT_TRUE(c.T_imu_cam.isApprox(eurocDescription().calibration.T_imu_cam, 1e-15));
  EXPECT_EQ(c.camera.width, kEurocWidth);
  EXPECT_EQ(c.camera.height, kEurocHeight);
  EXPECT_EQ(c.camera.fx, 4.58654);
  EXPECT_EQ(c.camera.cy, 2.48375);
  EXPECT_EQ(c.camera.distortion, DistortionModel::kRadialTangential);
  EXPECT_EQ(c.camera.distortion_coeffs, eurocDescription().calibration.camera.distortion_coeffs);
  std::size_t imu = 0, frames = 0;
  while (const std::optional<Measurement> m = reader->next()) {
    if (const auto* s = std::get_if<ImuSample>(&*m)) {
      const ImuSample want = eurocImuAt(1000 + 5 * static_cast<Time>(imu++));
      EXPECT_EQ(s->t, want.t);
      EXPECT_EQ(s->omega_imu, want.omega_imu);  // doubles written to round-trip exactly
      EXPECT_EQ(s->acc_imu, want.acc_imu);
    } else {
      const auto& f = std::get<CameraFrame>(*m);
      const CameraFrame want = eurocFrameAt(1003 + 50 * static_cast<Time>(frames++));
      EXPECT_EQ(f.t, want.t);
      EXPECT_EQ(f.image.data, want.image.data);  // PNG is lossless
    }
  }
  EXPECT_EQ(imu, 41u);
  EXPECT_EQ(frames, 4u);
  const GroundTruth& gt = reader->groundTruth();
  ASSERT_EQ(gt.poses.size(), 41u);
  EXPECT_EQ(gt.body_frame, "imu");
  for (const StampedPose& p : gt.poses)
    EXPECT_TRUE(p.T_world_body.isApprox(truthAt(p.t).T_world_imu, 1e-14)) << p.t;
}

TEST(EurocWriter, RefusesLidarScansAndRecordsThatDoNotAdvance) {
  TempDir tmp;
  EurocDatasetWriter w((tmp / "seq").string(), eurocDescription(), false);
  LidarScan scan;
  scan.t = 1000;
  EXPECT_THROW(w.add(scan), std::invalid_argument);
  w.add(eurocImuAt(1000));
  EXPECT_THROW(w.add(eurocImuAt(1000)), std::invalid_argument);
  w.add(eurocFrameAt(1000));
  EXPECT_THROW(w.add(eurocFrameAt(999)), std::invalid_argument);
  CameraFrame wrong_size = eurocFrameAt(1100);
  wrong_size.image.width = kEurocWidth - 1;
  EXPECT_THROW(w.add(std::move(wrong_size)), std::invalid_argument);
}

TEST(EurocWriter, AWriterThatDoesNotFinishLeavesNothingAndOnlyItsOwnOutputIsReplaced) {
  TempDir tmp;
  {
    EurocDatasetWriter w((tmp / "seq").string(), eurocDescription(), false);
    w.add(eurocImuAt(1000));
  }
  EXPECT_FALSE(fs::exists(tmp / "seq"));
  EXPECT_FALSE(fs::exists(tmp / "seq.partial"));
  writeEurocDataset(tmp / "seq");
  EXPECT_THROW(EurocDatasetWriter::checkOutput((tmp / "seq").string(), false), IoError);  // needs --force
  EXPECT_NO_THROW(EurocDatasetWriter::checkOutput((tmp / "seq").string(), true));
  test::writeText(tmp / "notes" / "todo.txt", "mine\n");
  EXPECT_THROW(EurocDatasetWriter::checkOutput((tmp / "notes").string(), true), IoError);
  test::writeText(tmp / "seq" / "todo.txt", "mine\n");  // the user's file beside an earlier output
  try {
    EurocDatasetWriter::checkOutput((tmp / "seq").string(), true);
    FAIL() << "a folder holding a file the writer did not write was accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("todo.txt"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace drover::io
