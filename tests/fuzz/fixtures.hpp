#pragma once
// Small valid datasets and files for the fuzz suite, written by the tests themselves (no shared data needed):
// a KITTI odometry sequence whose scans are ray-cast in a box-shaped hall (so `drover run` has real structure to
// match), a KITTI raw drive, a EuRoC sequence, a simulator folder, trajectories, a g2o graph and PNGs.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

// GCC 12 reports a false -Wstringop-overflow inside writePng when it is inlined with small constant sizes.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wstringop-overflow"
#include "io/kitti_fixture_util.hpp"
#pragma GCC diagnostic pop
#include "io/sim_dataset.hpp"
#include "support/temp_dir.hpp"

namespace drover::test::fuzz {
namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;

inline std::string numbers(std::initializer_list<double> v) {
  std::ostringstream ss;
  ss.precision(12);
  for (double x : v) ss << x << ' ';
  return ss.str();
}

// "a,b,c" without a trailing separator.
inline std::string csv(std::initializer_list<double> v) {
  std::string s = numbers(v);
  s.pop_back();
  for (char& c : s) c = c == ' ' ? ',' : c;
  return s;
}

// [m] range along `dir` from `origin` to the inside of the box [-20, 20] x [-8, 8] x [-1.7, 3.3] (lidar height 1.7 m),
// with a 1 m square pillar at (6, 3) so that the scene is not symmetric.
inline double rayToHall(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) {
  const Eigen::Vector3d lo(-20, -8, -1.7), hi(20, 8, 3.3);
  double best = 1e9;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(dir[a]) < 1e-12) continue;
    const double t = ((dir[a] > 0 ? hi[a] : lo[a]) - origin[a]) / dir[a];
    if (t > 0) best = std::min(best, t);
  }
  for (int a = 0; a < 2; ++a) {  // pillar faces x = 5.5 / 6.5, y = 2.5 / 3.5
    for (double face : {a == 0 ? 5.5 : 2.5, a == 0 ? 6.5 : 3.5}) {
      if (std::abs(dir[a]) < 1e-12) continue;
      const double t = (face - origin[a]) / dir[a];
      const Eigen::Vector3d p = origin + t * dir;
      const int b = 1 - a;
      const double lo_b = b == 0 ? 5.5 : 2.5;
      if (t > 0 && p[b] >= lo_b && p[b] <= lo_b + 1 && p.z() < 3.3) best = std::min(best, t);
    }
  }
  return best;
}

// A KITTI-style sweep (x, y, z, reflectance) from a lidar at `x` m along the hall, `rings` x `columns` rays.
inline std::vector<RawPoint> hallScan(double x, int rings, int columns) {
  std::vector<RawPoint> pts;
  const Eigen::Vector3d origin(x, 0.3 * std::sin(x), 0);
  for (int r = 0; r < rings; ++r) {
    const double el = (-24.8 + 26.8 * r / std::max(1, rings - 1)) * kPi / 180;  // HDL-64E's span
    for (int c = 0; c < columns; ++c) {
      const double az = 2 * kPi * c / columns;
      const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      const double range = rayToHall(origin, d);
      if (range > 80) continue;
      const Eigen::Vector3d p = range * d;
      pts.push_back({static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()),
                     static_cast<float>(0.1 + 0.01 * (c % 50))});
    }
  }
  return pts;
}

// sequences/00-like folder: velodyne/, image_2/, times.txt, calib.txt, poses.txt (camera-0 frame, 0.5 m a frame).
inline void writeKittiSequence(const fs::path& seq, int frames = 5, int rings = 16, int columns = 90) {
  std::string times, poses;
  for (int i = 0; i < frames; ++i) {
    char name[16];
    std::snprintf(name, sizeof(name), "%06d", i);
    writeBin(seq / "velodyne" / (std::string(name) + ".bin"), hallScan(0.5 * i, rings, columns));
    std::vector<std::uint8_t> rgb(8 * 6 * 3);
    for (std::size_t k = 0; k < rgb.size(); ++k) rgb[k] = static_cast<std::uint8_t>(k * 7 + i);
    writePng(seq / "image_2" / (std::string(name) + ".png"), 8, 6, 3, rgb);
    times += numbers({0.1 * i}) + "\n";
    poses += numbers({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5 * i}) + "\n";
  }
  writeText(seq / "times.txt", times);
  writeText(seq / "poses.txt", poses);
  const std::string p = "718.856 0 607.1928 ";
  writeText(seq / "calib.txt", "P0: " + p + "0 0 718.856 185.2157 0 0 0 1 0\n" + "P1: " + p +
                                   "-386.1448 0 718.856 185.2157 0 0 0 1 0\n" + "P2: " + p +
                                   "45.38225 0 718.856 185.2157 -0.1130887 0 0 1 0.003779761\n" + "P3: " + p +
                                   "-337.2877 0 718.856 185.2157 2.369057 0 0 1 0.004915215\n"
                                   "Tr: 0 -1 0 -0.01 0 0 -1 -0.05 1 0 0 -0.29\n");
}

inline std::string kittiRawStamp(int centis) {  // "2011-09-30 12:40:SS.ff0000000"
  char buf[64];
  std::snprintf(buf, sizeof(buf), "2011-09-30 12:40:%02d.%02d0000000", 21 + centis / 100, centis % 100);
  return buf;
}

// A KITTI raw sync drive (calibration in the drive folder): 10 oxts records at 10 Hz, 3 scans, 2 images.
inline void writeKittiRawDrive(const fs::path& drive) {
  writeText(drive / "calib_imu_to_velo.txt",
            "calib_time: 25-May-2012 16:47:16\nR: 1 0 0 0 1 0 0 0 1\nT: -0.81 0.32 -0.8\n");
  writeText(drive / "calib_velo_to_cam.txt",
            "calib_time: 15-Mar-2012 11:37:16\nR: 0 -1 0 0 0 -1 1 0 0\n"
            "T: -0.004 -0.076 -0.27\ndelta_f: 0 0\ndelta_c: 0 0\n");
  writeText(drive / "calib_cam_to_cam.txt",
            "calib_time: 09-Jan-2012 13:57:47\ncorner_dist: 9.950000e-02\nS_00: 1392 512\n"
            "K_00: 984.2 0 690 0 980.8 233.2 0 0 1\nD_00: -0.37 0.2 0.0022 0.0014 -0.072\n"
            "R_00: 1 0 0 0 1 0 0 0 1\nT_00: 0 0 0\nS_rect_00: 1242 375\nR_rect_00: 1 0 0 0 1 0 0 0 1\n"
            "P_rect_00: 721.5 0 609.6 0 0 721.5 172.9 0 0 0 1 0\nS_02: 1392 512\n"
            "K_02: 959.8 0 696 0 956.9 224.2 0 0 1\nD_02: -0.37 0.2 0.0009 -0.0008 -0.073\n"
            "R_02: 1 0 0 0 1 0 0 0 1\nT_02: 0.0599 -0.0013 0.0057\nS_rect_02: 1242 375\n"
            "P_rect_02: 721.5 0 609.6 44.86 0 721.5 172.9 0.2164 0 0 1 0.002746\n");
  std::string oxts_stamps;
  for (int k = 0; k < 10; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "%010d.txt", k);
    writeText(drive / "oxts" / "data" / name, numbers({49.0 + 1e-6 * k,
                                                       8.4 + 1e-5 * k,
                                                       110,
                                                       0.02,
                                                       -0.01,
                                                       0.3 + 0.02 * k,
                                                       1,
                                                       2,
                                                       10,
                                                       0,
                                                       0.5,
                                                       21,
                                                       22,
                                                       23,
                                                       0.1,
                                                       2,
                                                       9.81,
                                                       11,
                                                       12,
                                                       13,
                                                       0.001,
                                                       -0.002,
                                                       0.2,
                                                       0.05,
                                                       0.02,
                                                       4,
                                                       9,
                                                       5,
                                                       5,
                                                       6}) +
                                                  "\n");
    oxts_stamps += kittiRawStamp(10 * k) + "\n";
  }
  writeText(drive / "oxts" / "timestamps.txt", oxts_stamps);
  std::string start, end, mid;
  for (int i = 0; i < 3; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%010d.bin", i);
    writeBin(drive / "velodyne_points" / "data" / name, hallScan(0.5 * i, 4, 16));
    start += kittiRawStamp(10 + 20 * i) + "\n";
    end += kittiRawStamp(19 + 20 * i) + "\n";
    mid += kittiRawStamp(15 + 20 * i) + "\n";
  }
  writeText(drive / "velodyne_points" / "timestamps_start.txt", start);
  writeText(drive / "velodyne_points" / "timestamps_end.txt", end);
  writeText(drive / "velodyne_points" / "timestamps.txt", mid);
  std::string stamps;
  for (int i = 0; i < 2; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%010d.png", i);
    writePng(drive / "image_02" / "data" / name, 2, 2, 3, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12});
    stamps += kittiRawStamp(25 + 30 * i) + "\n";
  }
  writeText(drive / "image_02" / "timestamps.txt", stamps);
}

inline std::string eurocSensorYaml(bool camera) {
  std::string y = "%YAML:1.0\nsensor_type: " + std::string(camera ? "camera" : "imu") +
                  "\nT_BS:\n  cols: 4\n  rows: 4\n  data: [" +
                  (camera ? "0.0, -1.0, 0.0, 0.1,\n         1.0, 0.0, 0.0, 0.2,\n"
                          : "1.0, 0.0, 0.0, 0.0,\n         0.0, 1.0, 0.0, 0.0,\n") +
                  "         0.0, 0.0, 1.0, 0.0,\n         0.0, 0.0, 0.0, 1.0]\n";
  if (!camera) return y + "rate_hz: 200\n";
  return y +
         "rate_hz: 20\nresolution: [4, 3]\ncamera_model: pinhole\nintrinsics: [100.0, 101.0, 2.0, 1.5]\n"
         "distortion_model: radial-tangential\ndistortion_coefficients: [0.1, -0.01, 0.001, 0.0001]\n";
}

// SEQ/mav0 with imu0 (20 samples at 200 Hz), cam0 (3 PNGs) and the ground-truth CSV.
inline void writeEurocSequence(const fs::path& seq) {
  const fs::path mav = seq / "mav0";
  writeText(mav / "imu0" / "sensor.yaml", eurocSensorYaml(false));
  writeText(mav / "cam0" / "sensor.yaml", eurocSensorYaml(true));
  std::string imu = "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n", gt = "#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z\n";
  for (int k = 0; k < 20; ++k) {
    const long long t = 1'403'636'579'000'000'000LL + 5'000'000LL * k;
    imu += std::to_string(t) + "," + csv({0.01 * k, -0.02, 0.03, 0.1, 0.2, 9.81}) + "\n";
    gt += std::to_string(t) + "," + csv({0.01 * k, 0, 1, 1, 0, 0, 0}) + "\n";
  }
  writeText(mav / "imu0" / "data.csv", imu);
  writeText(mav / "state_groundtruth_estimate0" / "data.csv", gt);
  std::string cam = "#timestamp [ns],filename\n";
  for (int i = 0; i < 3; ++i) {
    const std::string t = std::to_string(1'403'636'579'010'000'000LL + 30'000'000LL * i);
    cam += t + "," + t + ".png\n";
    std::vector<std::uint8_t> grey(12);
    for (int k = 0; k < 12; ++k) grey[k] = static_cast<std::uint8_t>(10 * i + k);
    writePng(mav / "cam0" / "data" / (t + ".png"), 4, 3, 1, grey);
  }
  writeText(mav / "cam0" / "data.csv", cam);
}

// A simulator folder: 1 s of IMU at 200 Hz, 5 scans of 40 points with time and ring, 3 grey 8x6 frames.
inline void writeSimDataset(const fs::path& dir) {
  io::SimDatasetDescription d;
  d.calibration.T_imu_lidar.translation() = Eigen::Vector3d(0.05, 0, 0.3);
  CameraIntrinsics& k = d.calibration.camera;
  k.width = 8, k.height = 6, k.fx = 4.5, k.fy = 4.25, k.cx = 3.9, k.cy = 2.7;
  k.distortion = DistortionModel::kRadialTangential;
  k.distortion_coeffs = {-0.1, 0.01, 1e-4, -2e-4};
  d.scenario.name = "fuzz";
  d.scenario.duration_s = 1.0;
  io::SimDatasetWriter w(dir.string(), d);
  Trajectory gt;
  for (int i = 0; i <= 200; ++i) {
    const Time t = 5'000'000LL * i;
    ImuSample s;
    s.t = t;
    s.omega_imu = Eigen::Vector3d(0.01, -0.02, 0.03);
    s.acc_imu = Eigen::Vector3d(0.1, 0, 9.81);
    s.q_world_imu = Eigen::Quaterniond::Identity();
    w.add(s);
    if (i % 40 == 0) {
      LidarScan scan;
      scan.t = t, scan.t_end = t + 100'000'000, scan.has_time = scan.has_ring = true;
      for (const RawPoint& r : hallScan(0.01 * i, 4, 10)) {
        LidarPoint p;
        p.x = r[0], p.y = r[1], p.z = r[2], p.intensity = r[3];
        p.time_offset = 0.0025f * static_cast<float>(scan.points.size());
        p.ring = static_cast<std::uint16_t>(scan.points.size() / 10);
        scan.points.push_back(p);
      }
      w.add(std::move(scan));
    }
    if (i % 70 == 10) {
      CameraFrame f;
      f.t = t;
      f.image.width = 8, f.image.height = 6, f.image.channels = 1;
      for (int p = 0; p < 48; ++p) f.image.data.push_back(static_cast<std::uint8_t>(p * 5 + i));
      w.add(std::move(f));
    }
    StampedPose p;
    p.t = t;
    p.T_world_body.translation() = Eigen::Vector3d(0.01 * i, 0, 0);
    gt.push_back(p);
  }
  w.finish(gt);
}

// 20 poses on a gentle curve, as TUM, KITTI (+ times) and EuRoC CSV under dir.
inline void writeTrajectories(const fs::path& dir) {
  std::string tum, kitti, times, euroc = "#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z\n";
  for (int i = 0; i < 20; ++i) {
    const double yaw = 0.05 * i, c = std::cos(yaw), s = std::sin(yaw);
    const double x = 0.5 * i, y = 0.02 * i * i;
    tum += numbers({0.1 * i, x, y, 0, 0, 0, std::sin(yaw / 2), std::cos(yaw / 2)}) + "\n";
    kitti += numbers({c, -s, 0, x, s, c, 0, y, 0, 0, 1, 0}) + "\n";
    times += numbers({0.1 * i}) + "\n";
    euroc += std::to_string(1'000'000'000LL + 100'000'000LL * i) + "," +
             csv({x, y, 0, std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)}) + "\n";
  }
  writeText(dir / "traj.tum", tum);
  writeText(dir / "traj_kitti.txt", kitti);
  writeText(dir / "times.txt", times);
  writeText(dir / "traj_euroc.csv", euroc);
}

// A 6-vertex ring with one loop edge and a FIX line.
inline void writeG2oGraph(const fs::path& file) {
  std::string g;
  const std::string info = "100 0 0 0 0 0 100 0 0 0 0 100 0 0 0 400 0 0 400 0 400";
  for (int i = 0; i < 6; ++i)
    g += "VERTEX_SE3:QUAT " + std::to_string(i) + " " + numbers({1.0 * i, 0.1 * i, 0, 0, 0, 0, 1}) + "\n";
  for (int i = 0; i < 5; ++i)
    g += "EDGE_SE3:QUAT " + std::to_string(i) + " " + std::to_string(i + 1) + " 1 0.1 0 0 0 0 1 " + info + "\n";
  g += "EDGE_SE3:QUAT 0 5 5 0.5 0 0 0 0 1 " + info + "\n# a comment\nFIX 0\n";
  writeText(file, g);
}

// A PNG with texture (a checkerboard with a gradient) so detectors find corners.
inline void writeTexturedPng(const fs::path& file, int width, int height, int channels) {
  std::vector<std::uint8_t> px;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < channels; ++c)
        px.push_back(static_cast<std::uint8_t>((((x / 8) + (y / 8)) % 2 ? 200 : 40) + (x + y + 20 * c) % 30));
  writePng(file, width, height, channels, px);
}

}  // namespace drover::test::fuzz
