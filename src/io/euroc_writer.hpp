#pragma once
// Writes a simulated camera + IMU dataset in EuRoC MAV's ASL folder layout (Burri et al., IJRR 2016), the layout
// io/euroc_reader.hpp reads, so that `drover run --format euroc` runs on it exactly as on a real sequence:
//   SEQ/mav0/imu0/data.csv, sensor.yaml           t_ns, w [rad/s], a [m/s^2] in the IMU frame; T_BS = identity
//   SEQ/mav0/cam0/data.csv, sensor.yaml, data/    t_ns, <t_ns>.png (mono8); T_BS = T_imu_cam, intrinsics, rad-tan
//   SEQ/mav0/state_groundtruth_estimate0/data.csv t_ns, p, q (w x y z) of T_world_imu, v_world, b_w, b_a
//   SEQ/scenario.json                             Drover's scenario description (name, seed, path length)
// EuRoC's body frame B is its IMU's, so every T_BS is relative to the IMU. A lidar has no place in the layout:
// scans are refused. Staged as SEQ.partial and renamed when complete (io/output_paths.hpp).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "io/output_paths.hpp"
#include "io/sim_dataset.hpp"
#include "types/measurement.hpp"

namespace drover::io {

// One ground-truth state as EuRoC's state_groundtruth_estimate0 holds it.
struct EurocTruthState {
  Time t = 0;                                                      // [ns]
  Eigen::Isometry3d T_world_imu = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();               // [m/s]
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();             // [rad/s], IMU frame
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();            // [m/s^2], IMU frame
};

// "" when DIR (an existing folder) is empty or holds a dataset this writer wrote and nothing else, else why not.
std::string eurocDatasetProblem(const std::filesystem::path& dir);

class EurocDatasetWriter {
 public:
  // Throws IoError(DIR, "--out", why) when DIR may not be written (an existing DIR needs `overwrite` and must be
  // an earlier output of this writer), std::invalid_argument for a camera that is not mono8 or rad-tan/pinhole.
  EurocDatasetWriter(const std::string& dir, const SimDatasetDescription& description, bool overwrite);
  static void checkOutput(const std::string& dir, bool overwrite);
  // IMU samples and camera frames, each stream strictly increasing in time; anything else throws
  // std::invalid_argument naming the record.
  void add(Measurement&& m);
  // Writes the index files, the sensor files and the ground truth (strictly increasing), then publishes DIR.
  void finish(const std::vector<EurocTruthState>& truth);
  std::size_t imuCount() const { return imu_count_; }
  std::size_t frameCount() const { return frame_count_; }

 private:
  std::unique_ptr<StagedFolder> staged_;
  std::filesystem::path mav0_;
  SimDatasetDescription description_;
  std::string imu_csv_, camera_csv_;
  std::size_t imu_count_ = 0, frame_count_ = 0;
  Time last_imu_ = 0, last_frame_ = 0;
  bool finished_ = false;
};

}  // namespace drover::io
