#pragma once
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "types/time.hpp"

namespace drover {

enum class DistortionModel { kNone, kRadialTangential, kEquidistant };

// The name configs and dataset files use: "none", "radial-tangential", "equidistant".
inline const char* distortionModelName(DistortionModel m) {
  switch (m) {
    case DistortionModel::kRadialTangential:
      return "radial-tangential";
    case DistortionModel::kEquidistant:
      return "equidistant";
    case DistortionModel::kNone:
      break;
  }
  return "none";
}

// Pinhole intrinsics and distortion of one camera.
struct CameraIntrinsics {
  int width = 0, height = 0;          // [px]
  double fx = 0, fy = 0, cx = 0, cy = 0;  // [px]
  DistortionModel distortion = DistortionModel::kNone;
  // rad-tan: k1 k2 p1 p2 [k3]; equidistant: k1 k2 k3 k4.
  std::vector<double> distortion_coeffs;
};

// Sensor extrinsics, all relative to the IMU (body) frame, and time offsets.
struct Calibration {
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_imu_cam = Eigen::Isometry3d::Identity();
  CameraIntrinsics camera;
  // t_imu = t_sensor + offset [ns]; zero unless the dataset or config says otherwise.
  Time lidar_time_offset = 0;
  Time camera_time_offset = 0;
};

}  // namespace drover
