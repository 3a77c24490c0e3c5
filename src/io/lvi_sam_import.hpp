#pragma once
// LIO-SAM / LVI-SAM parameter files -> a Drover platform config (`drover config import-lvi-sam`), so that a user
// with an LVI-SAM setup switches in one step. Two kinds of file are understood:
//   - LIO-SAM's params.yaml and LVI-SAM's params_lidar.yaml: ROS parameters under one namespace key (lio_sam:,
//     lvi_sam:, or ROS 2's /**: ros__parameters:), e.g. N_SCAN, imuAccNoise, extrinsicRot;
//   - LVI-SAM's params_camera.yaml (VINS-Mono's format): an OpenCV FileStorage YAML (%YAML:1.0 first line,
//     !!opencv-matrix values with rows/cols/data), e.g. model_type, projection_parameters, extrinsicRotation.
// Frames and conventions (checked against LIO-SAM's imageProjection/imuPreintegration usage):
//   extrinsicRot = R_lidar_imu (rotates IMU vectors into the lidar frame), extrinsicTrans = t_lidar_imu (the IMU's
//   origin in the lidar frame), so T_imu_lidar = [R^T | -R^T t]; extrinsicRPY = R_lidar_orientation rotates the
//   9-axis unit's orientation output only. Camera: extrinsicRotation / extrinsicTranslation = T_imu_cam;
//   td: t_imu = t_image + td, which is Drover's camera_time_offset.
// Every key of every file ends up either mapped (with the Drover key it went to) or ignored (with the reason):
// nothing is dropped silently.
#include <string>
#include <vector>

namespace drover::io {

// One parameter file: the name used in messages and its whole text.
struct LviSamFile {
  std::string path;
  std::string text;
};

// A key of an input file and what became of it.
struct LviSamKey {
  std::string file;  // the input file's path
  std::string key;   // dotted as in the file: "lvi_sam.N_SCAN", "projection_parameters.fx"
  std::string note;  // mapped: the Drover key(s) it set, or why none is needed; ignored: why it is not used
};

struct LviSamImport {
  std::string yaml;  // the platform config, ending with a comment block that lists the ignored keys
  std::vector<LviSamKey> mapped;
  std::vector<LviSamKey> ignored;
};

// Pure: texts in, config out. Throws IoError naming the file (line and key where there is one) for text that is
// not YAML, a file of neither kind, two files of the same kind, or a value of the wrong type or range (a rotation
// that is not one, N_SCAN of 0). The config is not yet checked by Drover's loaders: the caller does that.
LviSamImport importLviSam(const std::vector<LviSamFile>& files);

// Reads the files (IoError naming a missing or unreadable one) and imports them.
LviSamImport importLviSamFiles(const std::vector<std::string>& paths);

}  // namespace drover::io
