#pragma once
// Platform config files (config/*.yaml). This reads the two sections that describe the data:
//
//   dataset:                     # what to read (all keys optional; defaults as in DatasetOptions)
//     lidar_topic / imu_topic / image_topic: ROS1 bag topics (strings)
//     ground_truth_topic: a bag's nav_msgs/Odometry ground truth (none when left out)
//     kitti_camera: 0..3          KITTI image folder (image_0 .. image_3)
//     load_lidar / load_imu / load_images: true | false
//   calibration:                 # for sources without their own calibration (bags); all keys optional
//     T_imu_lidar, T_imu_cam: 16 numbers, a row-major 4x4 rigid transform [m]
//     camera: {width, height [px], fx, fy, cx, cy [px], distortion_model: none | radial-tangential |
//              equidistant, distortion_coeffs: [k1, k2, p1, p2(, k3)] or [k1, k2, k3, k4]}
//     lidar_time_offset, camera_time_offset: [s] within +-3600, t_imu = t_sensor + offset
//
// The other top-level sections (`sim:`, `odometry:`) belong to other modules and are read by them; any other
// top-level name is an error naming its line (a misspelt section must not silently fall back to defaults). Inside these two sections an unknown
// key is an error naming it (a typo must not silently fall back to a default), as is a value of the wrong type. In
// every section a key written twice, and a section written twice, are errors naming both lines; numbers go through
// io/user_values.hpp as the command-line options do.
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "io/dataset.hpp"

namespace drover::io {

// Throws IoError naming the file, the line and the key on a missing file, invalid YAML, unknown key or bad value.
DatasetOptions loadDatasetOptions(const std::string& yaml_path);

// Helpers shared by YAML readers (configs, EuRoC sensor.yaml, OpenCV-written files).
// The file's text with OpenCV FileStorage's "%YAML:1.0" first line (which yaml-cpp rejects) turned into a comment,
// so line numbers still match the file. Throws IoError when the file cannot be read.
std::string readYamlText(const std::string& path);
// 16 numbers, row-major 4x4, as a rigid transform: the last row must be 0 0 0 1 and the rotation orthonormal within
// io::kRotationTolerance (then re-orthonormalised). Throws IoError naming file and record otherwise.
Eigen::Isometry3d rigidTransformFromRowMajor(const std::vector<double>& values, const std::string& file,
                                             const std::string& record);

}  // namespace drover::io
