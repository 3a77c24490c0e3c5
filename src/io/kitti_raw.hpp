#pragma once
// KITTI raw drives (Geiger et al., "Vision meets Robotics: The KITTI Dataset", IJRR 2013), both layouts:
//  - sync    (<date>_drive_NNNN_sync):    rectified images, velodyne_points/data/*.bin, 10 Hz oxts;
//  - extract (<date>_drive_NNNN_extract): unrectified images, velodyne_points/data/*.txt ("x y z r"), 100 Hz oxts.
// The layout is told by the scan files (.bin -> sync, .txt -> extract), else by the folder's "_extract" suffix.
// Calibration files (calib_imu_to_velo.txt, calib_velo_to_cam.txt, calib_cam_to_cam.txt) are looked up in the
// drive folder first, then in its parent (the date folder, as KITTI ships them).
//
// Frames: body = the OXTS IMU (x forward, y left, z up). T_imu_lidar = inv(T_velo_imu) (calib_imu_to_velo).
// Camera (image_00 or image_02 per DatasetOptions::kitti_camera):
//  - sync: rectified camera, T_imu_cam = T_imu_velo * T_velo_cam0 * inv([R_rect_00 | 0]) * (-K^-1 P_rect_0x(:,3)),
//    intrinsics from P_rect_0x, no distortion (the devkit's projection P_rect_0x * R_rect_00 * T_cam0_velo);
//  - extract: unrectified camera, T_imu_cam = T_imu_velo * T_velo_cam0 * inv([R_0x | T_0x]), intrinsics K_0x and
//    rad-tan distortion D_0x (k1 k2 p1 p2 k3).
// Time: ns since 1970-01-01 with KITTI's local date-time strings read as UTC (see parseKittiTimestamp).
// Scans: t = timestamps_start, t_end = timestamps_end (timestamps.txt when those are absent); no per-point time.
// Order at equal stamps: IMU, then lidar, then camera. A record or file whose stamp is not after the previous one of
// its stream (KITTI raw's timestamps do repeat and jump back now and then) is dropped and counted in drops().
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "io/reader.hpp"

namespace drover::io {

class KittiRawReader : public Reader {
 public:
  // Reads calibration, all oxts records and every timestamps file now; scans and images lazily in next().
  // Throws IoError for missing/malformed files or counts of data files that differ from their timestamps.
  KittiRawReader(const std::string& drive_dir, const DatasetOptions& options);

  std::optional<Measurement> next() override;
  const Calibration& calibration() const override { return calibration_; }
  // T_world_imu from the oxts (devkit convertOxtsToPose, relative to the first record), body "imu".
  const GroundTruth& groundTruth() const override { return ground_truth_; }
  std::string describe() const override;

  bool isSync() const { return sync_; }
  const std::vector<ImuSample>& imuSamples() const { return imu_; }

 private:
  // One lazily loaded stream of numbered files (velodyne_points or image_0x).
  struct FileStream {
    std::string data_dir;  // .../data
    std::string ext;       // "bin" | "txt" | "png"
    std::vector<Time> t;   // per file
    std::vector<Time> t_end;
    std::string stamps;      // the timestamps file t comes from, for warnings
    std::optional<Time> last;  // [ns] stamp of the last file returned
    std::size_t next = 0;
    bool enabled = false;
    bool hasNext() const { return enabled && next < t.size(); }
    std::string path(std::size_t i) const;
  };

  void readCalibration(const std::string& drive_dir);
  void readOxts(const std::string& drive_dir);
  FileStream indexStream(const std::string& folder, const std::string& ext, bool with_start_end) const;
  // Drops (with a counted warning) the files at the stream's head whose stamp is not after the last one returned.
  void skipStale(FileStream& stream);
  LidarScan loadScan();
  CameraFrame loadImage();

  std::string dir_;
  DatasetOptions options_;
  bool sync_ = true;
  Calibration calibration_;
  GroundTruth ground_truth_;
  std::vector<ImuSample> imu_;
  std::size_t next_imu_ = 0;
  FileStream scans_;
  FileStream images_;
};

std::unique_ptr<Reader> openKittiRaw(const std::string& drive_dir, const DatasetOptions& options);

}  // namespace drover::io
