#pragma once
// KITTI odometry benchmark sequences (sequences/NN with velodyne/, image_0/ or image_2/, times.txt, calib.txt and
// optionally poses.txt). Layout and conventions: Geiger et al., "Are we ready for autonomous driving?", CVPR 2012,
// and the odometry devkit readme.
//
// Frames: KITTI odometry has no IMU, so the body ("imu") frame of the Calibration is the lidar:
// T_imu_lidar = I, T_imu_cam = Tr^-1 * T_cam0_cam, where Tr = T_cam0_lidar (calib.txt, rectified camera 0) and
// T_cam0_cam is the rectified camera's offset (identity for camera 0; -K^-1 P2(:,3) for camera 2, i.e. the frame
// in which P2 projects with K alone; see rectifiedCameraOffset).
// Time: times.txt seconds since the sequence start -> ns. Each frame's scan has t = t_end = that time (KITTI
// timestamps a sweep once), the image the same time; at equal stamps the scan comes first.
// Unlike a sensor's stamps (which the other readers drop with a warning when they repeat or go back), a times.txt
// that does not strictly increase is an error naming the line: it is the frame index itself -- line k is
// velodyne/k.bin, image k and poses.txt line k, and trajectory_kitti.txt and the devkit pair poses by line -- so
// dropping a frame would shift every later pose against the ground truth. Non-finite points are dropped
// (LidarScan::dropped_nonfinite).
#include <memory>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "io/reader.hpp"

namespace drover::io {

class KittiOdometryReader : public Reader {
 public:
  // Reads times.txt, calib.txt and poses.txt (when present) now; scans and images lazily in next().
  // Throws IoError for a missing or malformed times/calib/poses file, std::invalid_argument for a
  // kitti_camera other than 0 or 2.
  KittiOdometryReader(const std::string& sequence_dir, const DatasetOptions& options);

  std::optional<Measurement> next() override;
  const Calibration& calibration() const override { return calibration_; }
  // Ground truth in the lidar frame: T_world_lidar(i) = Tr^-1 * T_cam0(0)_cam0(i) * Tr; empty for 11-21.
  const GroundTruth& groundTruth() const override { return ground_truth_; }
  std::string describe() const override;

  // Ground truth as KITTI gives it: T_cam0(0)_cam0(i) (camera-0 frame: x right, y down, z forward).
  const Trajectory& groundTruthCam0() const { return ground_truth_cam0_; }
  // Tr of calib.txt: maps lidar points into the rectified camera-0 frame.
  const Eigen::Isometry3d& T_cam0_lidar() const { return T_cam0_lidar_; }
  const std::vector<Time>& frameTimes() const { return times_; }
  std::string scanPath(std::size_t frame) const;
  std::string imagePath(std::size_t frame) const;

 private:
  std::string imageFolder() const;  // image_0 | image_2
  void readCalibration();
  void readGroundTruth();

  std::string dir_;
  DatasetOptions options_;
  std::vector<Time> times_;
  Calibration calibration_;
  Eigen::Isometry3d T_cam0_lidar_ = Eigen::Isometry3d::Identity();
  GroundTruth ground_truth_;
  Trajectory ground_truth_cam0_;
  std::size_t frame_ = 0;       // next frame to emit
  bool scan_done_ = false;      // the current frame's scan was emitted (or is not loaded)
};

std::unique_ptr<Reader> openKittiOdometry(const std::string& sequence_dir, const DatasetOptions& options);

}  // namespace drover::io
