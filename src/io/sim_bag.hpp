#pragma once
// `drover sim --format bag`: a simulated course as a ROS1 bag (io/bag_writer.hpp) in LVI-SAM's topic layout, so
// that Drover's bag reader and ROS nodes are tested on data with ground truth. config/farm_sim_bag.yaml reads it.
//
//   /points_raw        sensor_msgs/PointCloud2  frame "lidar"   one sweep, stamp = its start, Velodyne XYZIRT layout
//                                                                (io/ros_serialize.hpp), time [s] since the stamp
//   /imu_raw           sensor_msgs/Imu          frame "imu"     rate [rad/s], specific force [m/s^2] and orientation
//                                                                (9-axis), per-axis noise variances on the diagonals
//   /camera/image_raw  sensor_msgs/Image        frame "camera"  mono8 (bgr8 with camera_color), mid-exposure stamp
//   /ground_truth      nav_msgs/Odometry        frame "world", child "imu": T_world_imu, twist in the IMU frame, at
//                                                                the ground-truth rate (200 Hz by default)
//
// Stamps are the sensors' as in the folder (t_imu = t_sensor + offset; the offsets are in the platform config) plus
// kSimBagEpoch. Record times are when a driver could publish: the stamp, and for a sweep its last point's time,
// so `rosbag play` delivers a sweep after the IMU samples it spans, as a live system sees it. Messages lie in the
// bag in record-time order. A sensor the simulation leaves out (--no-camera) has no topic.
#include <cstdint>
#include <queue>
#include <string>
#include <vector>

#include "io/bag_writer.hpp"
#include "io/sim_dataset.hpp"
#include "types/measurement.hpp"

namespace drover::io {

inline constexpr const char* kSimBagLidarTopic = "/points_raw";
inline constexpr const char* kSimBagImuTopic = "/imu_raw";
inline constexpr const char* kSimBagImageTopic = "/camera/image_raw";
inline constexpr const char* kSimBagGroundTruthTopic = "/ground_truth";
// Bag time = simulated time + this: ROS time is unsigned and simulated time starts at 0 (a negative lidar offset
// even stamps before it), and ROS tools expect Unix times. 1.7e9 s = 2023-11-14 22:13:20 UTC.
constexpr Time kSimBagEpoch = Time{1'700'000'000} * kNanosPerSecond;

struct SimBagCounts {
  std::size_t imu = 0, lidar = 0, camera = 0, ground_truth = 0, lidar_points = 0;
  std::uint64_t bytes = 0;  // [bytes] of the bag
};

class SimBagWriter {
 public:
  // Why PATH may not be written (IoError(PATH, "--out", why)): see bag::BagWriter::checkOutput; `overwrite` is
  // --force and replaces only an earlier bag.
  static void checkOutput(const std::string& path, bool overwrite);

  // ground_truth: strictly increasing times (sim::Simulator::groundTruthStates()). Creates PATH.partial.
  SimBagWriter(const std::string& path, const SimDatasetDescription& description,
               std::vector<SimGroundTruthState> ground_truth, bool overwrite);

  // Measurements in the simulator's order: each sensor's stamps strictly increasing, all in non-decreasing stamp
  // order across sensors (std::invalid_argument otherwise).
  void add(Measurement&& m);
  // Writes what is pending and the rest of the ground truth, and renames PATH.partial to PATH.
  void finish();
  const SimBagCounts& counts() const { return counts_; }

 private:
  struct Pending {
    Time record = 0;
    std::uint64_t seq = 0;  // ties in record time keep the order of arrival
    std::uint32_t conn = 0;
    std::string data;
    bool operator>(const Pending& o) const { return record > o.record || (record == o.record && seq > o.seq); }
  };
  void push(std::uint32_t conn, Time record, std::string data);
  void release(Time bound);  // writes the ground truth and pending messages recorded at or before `bound`

  bag::BagWriter writer_;
  SimDatasetDescription description_;
  std::vector<SimGroundTruthState> ground_truth_;
  std::size_t ground_truth_next_ = 0;
  std::uint32_t lidar_conn_ = 0, imu_conn_ = 0, image_conn_ = 0, ground_truth_conn_ = 0;
  std::priority_queue<Pending, std::vector<Pending>, std::greater<Pending>> pending_;
  std::uint64_t seq_ = 0;
  Time last_stamp_[3] = {0, 0, 0};  // per Measurement alternative (IMU, lidar, camera) [ns], sim clock
  Time last_any_ = 0;
  SimBagCounts counts_;
};

}  // namespace drover::io
