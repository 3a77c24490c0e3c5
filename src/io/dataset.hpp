#pragma once
#include <cstddef>
#include <memory>
#include <string>

#include "io/reader.hpp"

namespace drover::io {

// What to read from a dataset and how; filled from the platform config (config/*.yaml) and CLI flags.
struct DatasetOptions {
  bool load_lidar = true;
  bool load_imu = true;
  bool load_images = true;
  int kitti_camera = 2;  // KITTI odometry image folder: 0 = image_0 (grey left), 2 = image_2 (colour left)
  // KITTI odometry: read only the first N frames of times.txt (0 = all). Lets a snippet that holds the first
  // frames of a sequence be read; without it a frame listed in times.txt but missing on disk is an error.
  std::size_t kitti_max_frames = 0;
  // ROS1 bag topics (LVI-SAM defaults).
  std::string lidar_topic = "/points_raw";
  std::string imu_topic = "/imu_raw";
  std::string image_topic = "/camera/image_raw";
  // nav_msgs/Odometry ground truth (T_world_body, body = its child_frame_id: imu or lidar); empty: none.
  std::string ground_truth_topic;
  // Used for bags, which carry no calibration.
  Calibration calibration;
};

// format: kitti | kitti-raw | euroc | bag | sim (Drover's simulated dataset, io/sim_dataset.hpp). Throws IoError
// for a missing or malformed dataset and std::invalid_argument for an unknown format.
std::unique_ptr<Reader> openDataset(const std::string& path, const std::string& format,
                                    const DatasetOptions& options);

}  // namespace drover::io
