#pragma once
// Serializers of the ROS1 messages Drover writes to bags (the inverse of io/ros_messages.hpp and
// io/ros_pointcloud.hpp): the wire format is the fields in declaration order, little-endian; strings and variable
// arrays prefixed by a uint32 length, fixed arrays not. Stamps are ROS times (uint32 seconds since the Unix epoch,
// uint32 nanoseconds): a Time outside [0, 2^32 s) throws std::invalid_argument, as does a value the message cannot
// carry (a non-finite point, an image that is neither mono8 nor bgr8).
#include <cstdint>
#include <string>
#include <string_view>

#include "io/ros_messages.hpp"
#include "types/camera.hpp"
#include "types/imu.hpp"
#include "types/lidar.hpp"

namespace drover::io::ros {

// Appends fields to a message.
class WireWriter {
 public:
  template <typename T>
  void put(T v) {
    const auto* p = reinterpret_cast<const char*>(&v);
    out_.append(p, sizeof(T));
  }
  void bytes(const void* data, std::size_t n) { out_.append(static_cast<const char*>(data), n); }
  void string(std::string_view s);  // uint32 length + bytes
  std::string& buffer() { return out_; }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

// std_msgs/Header.
void writeHeader(WireWriter& out, std::uint32_t seq, Time stamp, std::string_view frame_id);

// Bytes per point of the cloud serializePointCloud2 writes.
constexpr std::uint32_t kVelodynePointStep = 22;

// sensor_msgs/PointCloud2 in the layout of the ROS Velodyne driver (velodyne_pointcloud's PointXYZIRT), which
// LVI-SAM and LIO-SAM read: one row (height 1) of packed 22-byte points, fields x, y, z, intensity (float32,
// offsets 0, 4, 8, 12), ring (uint16, 16) and time (float32, 18: seconds since the header stamp). The header stamp is
// scan.t, the sweep's start, so every time is the point's time_offset, >= 0. is_dense: true (no NaN points).
std::string serializePointCloud2(const LidarScan& scan, std::uint32_t seq, std::string_view frame_id);

// Per-axis variances the IMU message states [(rad/s)^2, (m/s^2)^2]; 0 = unknown (REP 145: all-zero covariance).
struct ImuVariances {
  double gyro = 0, accel = 0;
};

// sensor_msgs/Imu. Without s.q_world_imu the orientation is zero with orientation_covariance[0] = -1 (REP 145: no
// estimate); with it the orientation covariance is zero (unknown).
std::string serializeImu(const ImuSample& s, std::uint32_t seq, std::string_view frame_id,
                         const ImuVariances& variances = {});

// sensor_msgs/Image, mono8 (1 channel) or bgr8 (3), rows packed (step = width * channels), stamp frame.t.
std::string serializeImage(const CameraFrame& frame, std::uint32_t seq, std::string_view frame_id);

// nav_msgs/Odometry with o.frame_id and o.child_frame_id, zero (unknown) covariances.
std::string serializeOdometry(const Odometry& o, std::uint32_t seq);

}  // namespace drover::io::ros
