#pragma once
// EuRoC MAV datasets in the ASL folder layout:
//   SEQ/mav0/imu0/data.csv       "t_ns, w_x, w_y, w_z [rad/s], a_x, a_y, a_z [m/s^2]" ('#' header)
//   SEQ/mav0/imu0/sensor.yaml    T_BS (IMU -> body)
//   SEQ/mav0/cam0/data.csv       "t_ns, filename" of mono8 PNGs in cam0/data/
//   SEQ/mav0/cam0/sensor.yaml    T_BS (camera -> body), resolution, intrinsics, distortion
//   ground truth: SEQ/mav0/state_groundtruth_estimate0/data.csv, else SEQ/groundtruth_tum.txt (TUM)
// EuRoC's ground truth is the pose of the body frame B, which is the IMU frame (its T_BS is identity); we
// nonetheless compose with T_B_imu so the ground truth is exactly T_world_imu.
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>

#include "io/dataset.hpp"
#include "io/reader.hpp"
#include "types/calibration.hpp"

namespace drover::io {

// `dir` is the sequence folder holding mav0/, or mav0 itself. Indexes IMU samples, image stamps, calibration
// and ground truth up front; images are decoded lazily in next(). IMU and camera are merged in time order
// (IMU first on equal stamps). options.load_imu / load_images are honoured (lidar: EuRoC has none).
// Throws IoError naming file and record on any bad input, except that an IMU row or image whose stamp does not
// advance is dropped with a warning in Reader::drops().
std::unique_ptr<Reader> openEuroc(const std::string& dir, const DatasetOptions& options);

// T_BS of one EuRoC sensor.yaml: sensor -> body. Accepts OpenCV's "%YAML:1.0" first line.
Eigen::Isometry3d readEurocSensorExtrinsics(const std::string& sensor_yaml);

// Calibration from mav0/imu0/sensor.yaml and mav0/cam0/sensor.yaml: T_imu_cam = inv(T_B_imu) * T_B_cam,
// camera intrinsics and distortion. EuRoC has no lidar (T_imu_lidar stays identity) and no time offsets.
Calibration readEurocCalibration(const std::string& mav0_dir);

// The IMU noise figures of mav0/imu0/sensor.yaml (Kalibr's continuous-time densities). The reader does not use
// them: the estimators take theirs from the platform config (odometry.imu), which may inflate them on purpose.
// They are read so that a config that disagrees with the sensor can be reported. A figure the file does not give is
// empty; one that is given but is not a finite number >= 0 throws IoError naming the file and key.
struct EurocImuNoise {
  std::string file;                               // the sensor.yaml read
  std::optional<double> gyroscope_noise_density;  // [rad/s/sqrt(Hz)]
  std::optional<double> gyroscope_random_walk;    // [rad/s^2/sqrt(Hz)]
  std::optional<double> accelerometer_noise_density;  // [m/s^2/sqrt(Hz)]
  std::optional<double> accelerometer_random_walk;    // [m/s^3/sqrt(Hz)]
};
// `dir` as for openEuroc.
EurocImuNoise readEurocImuNoise(const std::string& dir);

}  // namespace drover::io
