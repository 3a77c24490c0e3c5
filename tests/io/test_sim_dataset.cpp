// The simulated-dataset folder: writer -> reader round trip on hand-made measurements, and a clear error for
// each kind of damage.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "io/dataset.hpp"
#include "io/sim_dataset.hpp"
#include "io/text_parsing.hpp"
#include "support/expect_io_error.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;
using test::expectIoError;
using test::TempDir;

constexpr int kWidth = 8, kHeight = 6;

SimDatasetDescription description() {
  SimDatasetDescription d;
  d.calibration.T_imu_lidar.translation() = Eigen::Vector3d(0.05, 0, 0.3);
  d.calibration.T_imu_cam.linear() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  d.calibration.T_imu_cam.translation() = Eigen::Vector3d(0.2, -0.01, 0.1);
  d.calibration.camera_time_offset = 5'000'000;
  d.calibration.lidar_time_offset = -123;
  CameraIntrinsics& k = d.calibration.camera;
  k.width = kWidth, k.height = kHeight, k.fx = 4.5, k.fy = 4.25, k.cx = 3.9, k.cy = 2.7;
  k.distortion = DistortionModel::kRadialTangential;
  k.distortion_coeffs = {-0.1, 0.01, 1e-4, -2e-4};
  d.sensors.gyro_noise_density = 1.7e-4;
  d.sensors.camera_pixel_samples = 3;
  d.sensors.camera_texture_filter = true;
  d.sensors.camera_edge_pixel_samples = 4;
  d.scenario.name = "hand-made";
  d.scenario.seed = 42;
  d.scenario.duration_s = 1.5;
  d.scenario.segments = {{"straight", 0, 500}, {"white-walls", 400, 900}};
  return d;
}

ImuSample imuAt(Time t) {
  ImuSample s;
  s.t = t;
  s.omega_imu = Eigen::Vector3d(0.1 + 1e-17 * static_cast<double>(t), -1.0 / 3.0, std::sqrt(2.0));
  s.acc_imu = Eigen::Vector3d(9.81, 1e-300, -0.1 * static_cast<double>(t));
  s.q_world_imu = Eigen::Quaterniond(Eigen::AngleAxisd(0.001 * static_cast<double>(t), Eigen::Vector3d::UnitZ()));
  return s;
}

LidarScan scanAt(Time t, int points) {
  LidarScan scan;
  scan.t = t;
  scan.t_end = t + 100'000'000;
  scan.has_time = scan.has_ring = true;
  for (int i = 0; i < points; ++i) {
    LidarPoint p;
    p.x = 1.0f / static_cast<float>(i + 3), p.y = -7.25f * static_cast<float>(i), p.z = 1e-30f;
    p.intensity = 255.0f / static_cast<float>(i + 1);
    p.time_offset = static_cast<float>(i) * 0.0123f;
    p.ring = static_cast<std::uint16_t>(i % 16);
    scan.points.push_back(p);
  }
  return scan;
}

CameraFrame frameAt(Time t) {
  CameraFrame f;
  f.t = t;
  f.image.width = kWidth, f.image.height = kHeight, f.image.channels = 1;
  for (int i = 0; i < kWidth * kHeight; ++i) f.image.data.push_back(static_cast<std::uint8_t>(i * 5 + t % 7));
  return f;
}

// IMU every 10 ns from 0 to 200, scans at 0, 100, 200 (ties with IMU), frames at 50, 100 (a three-way tie).
std::vector<Measurement> measurements() {
  std::vector<Measurement> m;
  for (Time t = 0; t <= 200; t += 10) m.push_back(imuAt(t));
  for (Time t = 0; t <= 200; t += 100) m.push_back(scanAt(t, 5));
  m.push_back(frameAt(50));
  m.push_back(frameAt(100));
  return m;
}

Trajectory groundTruth() {
  Trajectory gt;
  for (Time t = 0; t <= 200; t += 5) {
    StampedPose p;
    p.t = t;
    p.T_world_body.translation() = Eigen::Vector3d(0.1 * static_cast<double>(t), 2.0, -1.0 / 7.0);
    p.T_world_body.linear() = Eigen::AngleAxisd(0.01 * static_cast<double>(t), Eigen::Vector3d::UnitZ()).matrix();
    gt.push_back(p);
  }
  return gt;
}

fs::path writeDataset(const TempDir& tmp) {
  const fs::path dir = tmp / "ds";
  SimDatasetWriter w(dir.string(), description());
  for (Measurement& m : measurements()) w.add(std::move(m));
  w.finish(groundTruth());
  return dir;
}

std::vector<Measurement> readAll(const fs::path& dir) {
  auto reader = openDataset(dir.string(), "sim", DatasetOptions{});
  std::vector<Measurement> out;
  while (auto m = reader->next()) out.push_back(std::move(*m));
  return out;
}

void replaceInFile(const fs::path& p, const std::string& from, const std::string& to) {
  std::string text = readTextFile(p.string());
  const auto pos = text.find(from);
  ASSERT_NE(pos, std::string::npos) << from;
  text.replace(pos, from.size(), to);
  test::writeText(p, text);
}

TEST(SimDataset, RoundTripIsExactAndTimeOrderedWithTiesImuLidarCamera) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  const std::vector<Measurement> got = readAll(dir);
  ASSERT_EQ(got.size(), 21u + 3u + 2u);
  // At t = 100: IMU, then lidar, then camera.
  std::vector<std::size_t> kinds_at_100;
  for (const Measurement& m : got)
    if (measurementTime(m) == 100) kinds_at_100.push_back(m.index());
  EXPECT_EQ(kinds_at_100, (std::vector<std::size_t>{0, 1, 2}));
  for (std::size_t i = 1; i < got.size(); ++i) EXPECT_LE(measurementTime(got[i - 1]), measurementTime(got[i]));
  for (const Measurement& m : got) {
    if (const auto* s = std::get_if<ImuSample>(&m)) {
      const ImuSample e = imuAt(s->t);
      EXPECT_EQ(s->omega_imu, e.omega_imu);  // shortest round-trip text: bit-exact
      EXPECT_EQ(s->acc_imu, e.acc_imu);
      ASSERT_TRUE(s->q_world_imu.has_value());
      EXPECT_LT((s->q_world_imu->coeffs() - e.q_world_imu->coeffs()).norm(), 1e-15);
    } else if (const auto* scan = std::get_if<LidarScan>(&m)) {
      const LidarScan e = scanAt(scan->t, 5);
      EXPECT_EQ(scan->t_end, e.t_end);
      EXPECT_TRUE(scan->has_time && scan->has_ring);
      ASSERT_EQ(scan->points.size(), e.points.size());
      for (std::size_t i = 0; i < e.points.size(); ++i) {
        const LidarPoint &a = scan->points[i], &b = e.points[i];
        EXPECT_EQ(std::memcmp(&a.x, &b.x, 16), 0) << "x, y, z, intensity bit-exact, point " << i;
        EXPECT_EQ(a.ring, b.ring);
        EXPECT_NEAR(a.time_offset, b.time_offset, 0.6e-9 + 1e-7 * b.time_offset);  // stored as integer ns
      }
    } else {
      const auto& f = std::get<CameraFrame>(m);
      EXPECT_EQ(f.image.data, frameAt(f.t).image.data);
      EXPECT_EQ(f.image.channels, 1);
    }
  }
}

TEST(SimDataset, CalibrationGroundTruthAndScenarioReadBack) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  auto reader = openSimDataset(dir.string(), DatasetOptions{});
  const SimDatasetDescription d = description();
  const Calibration& c = reader->calibration();
  EXPECT_TRUE(c.T_imu_lidar.isApprox(d.calibration.T_imu_lidar, 1e-15));
  EXPECT_TRUE(c.T_imu_cam.isApprox(d.calibration.T_imu_cam, 1e-15));
  EXPECT_EQ(c.camera_time_offset, 5'000'000);
  EXPECT_EQ(c.lidar_time_offset, -123);
  EXPECT_EQ(c.camera.distortion, DistortionModel::kRadialTangential);
  EXPECT_EQ(c.camera.distortion_coeffs, d.calibration.camera.distortion_coeffs);
  EXPECT_EQ(c.camera.fx, 4.5);
  EXPECT_EQ(c.camera.cy, 2.7);
  const GroundTruth& gt = reader->groundTruth();
  EXPECT_EQ(gt.body_frame, "imu");
  const Trajectory e = groundTruth();
  ASSERT_EQ(gt.poses.size(), e.size());
  for (std::size_t i = 0; i < e.size(); ++i) {
    EXPECT_EQ(gt.poses[i].t, e[i].t);
    EXPECT_TRUE(gt.poses[i].T_world_body.isApprox(e[i].T_world_body, 1e-14));
  }
  const SimDatasetDescription r = readSimDescription(dir.string());
  EXPECT_EQ(r.scenario.name, "hand-made");
  EXPECT_EQ(r.scenario.seed, 42u);
  ASSERT_EQ(r.scenario.segments.size(), 2u);
  EXPECT_EQ(r.scenario.segments[1].condition, "white-walls");
  EXPECT_EQ(r.scenario.segments[1].end, 900);
  EXPECT_EQ(r.sensors.gyro_noise_density, 1.7e-4);
  EXPECT_EQ(r.sensors.lidar_model, "vlp16");
  EXPECT_EQ(r.sensors.camera_pixel_samples, 3);
  EXPECT_TRUE(r.sensors.camera_texture_filter);
  EXPECT_EQ(r.sensors.camera_edge_pixel_samples, 4);
  EXPECT_NE(reader->describe().find("hand-made"), std::string::npos);
}

TEST(SimDataset, LoadOptionsDropStreams) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  DatasetOptions o;
  o.load_imu = o.load_images = false;
  auto reader = openSimDataset(dir.string(), o);
  std::size_t scans = 0, others = 0;
  while (auto m = reader->next()) (std::holds_alternative<LidarScan>(*m) ? scans : others)++;
  EXPECT_EQ(scans, 3u);
  EXPECT_EQ(others, 0u);
}

TEST(SimDatasetWriter, RefusesAnExistingFolderUnlessOverwriting) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  expectIoError([&] { SimDatasetWriter(dir.string(), description()); }, {"(--out)", "already exists", "--force"});
  SimWriterOptions o;
  o.overwrite = true;
  SimDatasetWriter w(dir.string(), description(), o);
  w.add(imuAt(7));
  w.finish(groundTruth());
  EXPECT_EQ(readAll(dir).size(), 1u);  // replaced
}

TEST(SimDatasetWriter, OverwritesOnlyADatasetAndNeverTheWorkingFolder) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  test::writeText(dir / "notes.txt", "the user's");
  SimWriterOptions o;
  o.overwrite = true;
  expectIoError([&] { SimDatasetWriter(dir.string(), description(), o); },
                {"(--out)", "holds notes.txt, which drover sim does not write"});
  EXPECT_TRUE(fs::exists(dir / "notes.txt"));
  EXPECT_TRUE(fs::exists(dir / "calibration.yaml"));
  fs::remove(dir / "notes.txt");
  EXPECT_EQ(simDatasetProblem(dir), "");
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  expectIoError([&] { SimDatasetWriter(".", description(), o); }, {"(--out)", "working folder"});
  fs::current_path(cwd);
  EXPECT_TRUE(fs::exists(dir / "calibration.yaml"));
}

TEST(SimDatasetWriter, InterruptedWriteLeavesNoDatasetBehind) {
  TempDir tmp;
  const fs::path dir = tmp / "ds";
  {
    SimDatasetWriter w(dir.string(), description());
    w.add(imuAt(0));
    w.add(frameAt(3));
    EXPECT_TRUE(fs::exists(w.partialDir()));
    EXPECT_FALSE(fs::exists(dir));
  }  // destroyed without finish()
  EXPECT_FALSE(fs::exists(dir));
  EXPECT_FALSE(fs::exists(tmp / "ds.partial"));
}

TEST(SimDatasetWriter, RejectsTimeGoingBackwardsAndBadImages) {
  TempDir tmp;
  SimDatasetWriter w((tmp / "ds").string(), description());
  w.add(imuAt(10));
  EXPECT_THROW(w.add(imuAt(10)), std::invalid_argument);
  w.add(scanAt(10, 2));
  EXPECT_THROW(w.add(scanAt(5, 2)), std::invalid_argument);
  CameraFrame f = frameAt(20);
  f.image.width = 4;
  EXPECT_THROW(w.add(std::move(f)), std::invalid_argument);
  LidarScan s = scanAt(30, 2);
  s.points[1].ring = 16;  // vlp16 has rings 0..15
  EXPECT_THROW(w.add(std::move(s)), std::invalid_argument);
}

// ---- damaged datasets: one error each, naming file and record ------------------------------------------------

TEST(SimDatasetReader, MissingCalibrationFileIsNamed) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  fs::remove(dir / "calibration.yaml");
  expectIoError([&] { openSimDataset(dir.string(), {}); }, {"calibration.yaml", "not found"});
}

TEST(SimDatasetReader, MissingCalibrationKeyIsNamed) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  replaceInFile(dir / "calibration.yaml", "  T_imu_cam:", "  T_imu_camera:");
  expectIoError([&] { openSimDataset(dir.string(), {}); }, {"calibration.yaml", "calibration.T_imu_cam", "missing"});
  const fs::path dir2 = tmp / "ds2";
  fs::copy(dir, dir2, fs::copy_options::recursive);
  replaceInFile(dir2 / "calibration.yaml", "T_imu_camera:", "T_imu_cam:");
  replaceInFile(dir2 / "calibration.yaml", "    rings: 16\n", "");
  expectIoError([&] { openSimDataset(dir2.string(), {}); }, {"sensors.lidar.rings", "missing"});
}

TEST(SimDatasetReader, CameraPixelSamplesOutOfRangeIsNamed) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  replaceInFile(dir / "calibration.yaml", "    pixel_samples: 3", "    pixel_samples: 9");
  expectIoError([&] { openSimDataset(dir.string(), {}); }, {"calibration.yaml", "sensors.camera.pixel_samples", "[1, 4]"});
}

// Frames rendered before the texture filter existed were point-sampled textures: no key reads as false.
TEST(SimDatasetReader, TheTextureFilterIsReadAsWrittenFalseWhenAbsentAndAWordIsNamed) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  replaceInFile(dir / "calibration.yaml", "    texture_filter: true", "    texture_filter: yes please");
  expectIoError([&] { openSimDataset(dir.string(), {}); },
                {"calibration.yaml", "sensors.camera.texture_filter", "true or false", "yes please"});
  replaceInFile(dir / "calibration.yaml", "    texture_filter: yes please", "    texture_filter: false");
  EXPECT_FALSE(readSimDescription(dir.string()).sensors.camera_texture_filter);
  replaceInFile(dir / "calibration.yaml", "    texture_filter: false", "");
  EXPECT_FALSE(readSimDescription(dir.string()).sensors.camera_texture_filter);
}

// Frames rendered before edge rays existed took the same rays in every pixel: no key reads as 0 (off).
TEST(SimDatasetReader, EdgePixelSamplesAreReadAsWrittenOffWhenAbsentAndOutOfRangeNamed) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  replaceInFile(dir / "calibration.yaml", "    edge_pixel_samples: 4", "    edge_pixel_samples: 8");
  expectIoError([&] { openSimDataset(dir.string(), {}); },
                {"calibration.yaml", "sensors.camera.edge_pixel_samples", "[0, 4]"});
  replaceInFile(dir / "calibration.yaml", "    edge_pixel_samples: 8", "");
  EXPECT_EQ(readSimDescription(dir.string()).sensors.camera_edge_pixel_samples, 0);
}

TEST(SimDatasetReader, ScanFileSizeNotAMultipleOfTheRecordIsNamed) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  std::ofstream(dir / "lidar" / "000001.bin", std::ios::binary | std::ios::app) << "xyz";
  expectIoError([&] { readAll(dir); }, {"000001.bin", "not a multiple of the 24-byte"});
}

TEST(SimDatasetReader, NanPointIsDroppedAndCountedInItsScan) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  std::fstream f(dir / "lidar" / "000002.bin", std::ios::binary | std::ios::in | std::ios::out);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  f.seekp(3 * 24 + 4);  // point 3, y
  f.write(reinterpret_cast<const char*>(&nan), 4);
  f.close();
  const auto reader = openSimDataset(dir.string(), {});
  std::size_t points = 0, dropped = 0;
  while (auto m = reader->next()) {
    if (const auto* scan = std::get_if<LidarScan>(&*m)) {
      points += scan->points.size();
      dropped += scan->dropped_nonfinite;
    }
  }
  EXPECT_EQ(dropped, 1u);
  EXPECT_GT(points, 0u);
}

TEST(SimDatasetReader, NanInImuCsvIsNamedByLine) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  // The sample at t = 20 ns: its first value (omega x) becomes "nan".
  std::string text = readTextFile((dir / "imu.csv").string());
  const std::size_t start = text.find("\n20,") + 4, end = text.find(',', start);
  text.replace(start, end - start, "nan");
  test::writeText(dir / "imu.csv", text);
  expectIoError([&] { openSimDataset(dir.string(), {}); }, {"imu.csv", "line 4"});
}

TEST(SimDatasetReader, ImuSampleWhoseTimeGoesBackwardsIsDroppedWithAWarningNamingTheLine) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  replaceInFile(dir / "imu.csv", "\n30,", "\n15,");
  const auto reader = openSimDataset(dir.string(), {});
  ASSERT_EQ(reader->drops().measurements, 1u);
  EXPECT_NE(reader->drops().notices.at(0).find("imu.csv (line 5): dropped: timestamp goes back"), std::string::npos)
      << reader->drops().notices.at(0);
}

TEST(SimDatasetReader, ScanWhoseTimeGoesBackwardsIsDroppedAndTheNextScanIsStillItsOwnFile) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  replaceInFile(dir / "lidar" / "timestamps.csv", "1,100,", "1,0,");
  // Were scan 2 read from scan 1's file, this would fail the read.
  std::ofstream(dir / "lidar" / "000001.bin", std::ios::binary | std::ios::app) << "xyz";
  DatasetOptions options;
  options.load_imu = options.load_images = false;
  const auto reader = openSimDataset(dir.string(), options);
  std::vector<Time> t;
  while (auto m = reader->next()) t.push_back(std::get<LidarScan>(*m).t);
  EXPECT_EQ(t, (std::vector<Time>{0, 200}));
  ASSERT_EQ(reader->drops().measurements, 1u);
  EXPECT_NE(reader->drops().notices.at(0).find("timestamps.csv (line 3): dropped: timestamp 0.000000000 s repeats"),
            std::string::npos)
      << reader->drops().notices.at(0);
}

TEST(SimDatasetReader, MissingScanFileIsNamed) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  fs::remove(dir / "lidar" / "000001.bin");
  expectIoError([&] { readAll(dir); }, {"000001.bin", "lidar/timestamps.csv line 3", "not found"});
}

TEST(SimDatasetReader, MissingImageFileIsNamed) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  fs::remove(dir / "camera" / "000000.png");
  expectIoError([&] { readAll(dir); }, {"000000.png", "camera/timestamps.csv line 2", "not found"});
}

TEST(SimDatasetReader, MissingImuFileIsNamed) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  fs::remove(dir / "imu.csv");
  expectIoError([&] { openSimDataset(dir.string(), {}); }, {"imu.csv", "not found"});
}

TEST(SimDatasetReader, RingBeyondTheLidarsRingsIsNamed) {
  TempDir tmp;
  const fs::path dir = writeDataset(tmp);
  replaceInFile(dir / "calibration.yaml", "rings: 16", "rings: 4");
  expectIoError([&] { readAll(dir); }, {"000000.bin", "point 4", "ring 4 >= 4"});
}

}  // namespace
}  // namespace drover::io
