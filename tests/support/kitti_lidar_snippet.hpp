#pragma once
// Lidar-only odometry on one of the real KITTI snippets in ../shared (the first 10 scans of a sequence), with the
// shipped config/kitti.yaml exactly as `drover run` reads it. Shared by the system tests that judge it against the
// reference (test_kitti_lidar_odometry) and against the camera (test_kitti_camera_crosscheck).
#include <algorithm>
#include <string>

#include "io/config.hpp"
#include "io/dataset.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "support/shared_data.hpp"

namespace drover::test {

struct KittiLidarSnippet {
  Trajectory estimate, truth;  // T_world_lidar of the 10 scans (truth: the official poses, in the lidar frame)
  pipeline::OdometryStats stats;
};

inline KittiLidarSnippet runKittiLidarSnippet(const std::string& sequence) {
  const std::string config = std::string(DROVER_SOURCE_DIR) + "/config/kitti.yaml";
  io::DatasetOptions options = io::loadDatasetOptions(config);
  options.load_images = false;
  options.kitti_max_frames = 10;
  auto reader = io::openDataset(sharedData("kitti/sequences/" + sequence).string(), "kitti", options);
  pipeline::LidarOdometry odometry(io::loadOdometryConfig(config), reader->calibration());
  while (auto m = reader->next()) odometry.process(*m);
  odometry.finish();
  KittiLidarSnippet r{odometry.trajectory(), reader->groundTruth().poses, odometry.stats()};
  r.truth.resize(std::min(r.truth.size(), r.estimate.size()));
  return r;
}

}  // namespace drover::test
