#pragma once
// Decoders of serialized ROS1 messages (the wire format: little-endian fields in declaration order; strings and
// variable arrays prefixed by a uint32 length; fixed arrays not). Pure functions of the bytes: they throw
// MessageError with what was wrong, and the bag reader adds the file, topic and message index.
#include <Eigen/Geometry>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>

#include "types/camera.hpp"
#include "types/imu.hpp"
#include "types/lidar.hpp"

namespace drover::io::ros {

// Message types and md5sums (ROS Noetic common_msgs) the reader accepts on its topics.
inline constexpr std::string_view kPointCloud2 = "sensor_msgs/PointCloud2";
inline constexpr std::string_view kPointCloud2Md5 = "1158d486dd51d683ce2f1be655c3c181";
inline constexpr std::string_view kImu = "sensor_msgs/Imu";
inline constexpr std::string_view kImuMd5 = "6a62c6daae103f4ff57a132d6f95cec2";
inline constexpr std::string_view kImage = "sensor_msgs/Image";
inline constexpr std::string_view kImageMd5 = "060021388200f6f0f447d0fcd9c64743";
inline constexpr std::string_view kCompressedImage = "sensor_msgs/CompressedImage";
inline constexpr std::string_view kCompressedImageMd5 = "8f7a12909da2c9d3332d540a0977563f";
inline constexpr std::string_view kOdometry = "nav_msgs/Odometry";  // ground truth of simulated bags
inline constexpr std::string_view kOdometryMd5 = "cd5e73d190d741a2f92e81eda573aca7";

class MessageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bounds-checked sequential reader over one serialized message.
class WireReader {
 public:
  WireReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  template <typename T>
  T get() {
    T v;
    std::memcpy(&v, take(sizeof(T)), sizeof(T));
    return v;
  }
  const std::uint8_t* take(std::size_t n) {
    if (n > size_ - pos_)
      throw MessageError("message is cut off: needs " + std::to_string(n) + " more bytes at byte " +
                         std::to_string(pos_) + " of " + std::to_string(size_));
    const std::uint8_t* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  std::string string() {
    const auto n = get<std::uint32_t>();
    const auto* p = take(n);
    return {reinterpret_cast<const char*>(p), n};
  }
  std::size_t remaining() const { return size_ - pos_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

// std_msgs/Header.
struct Header {
  std::uint32_t seq = 0;
  Time stamp = 0;  // [ns] since the ROS epoch (Unix time)
  std::string frame_id;
};
Header readHeader(WireReader& in);

// nav_msgs/Odometry: the pose of child_frame_id in frame_id and the twist in child_frame_id (REP 105). The
// covariances are not kept.
struct Odometry {
  Time t = 0;  // [ns] header stamp
  std::string frame_id, child_frame_id;
  Eigen::Isometry3d T_frame_child = Eigen::Isometry3d::Identity();  // [m]
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();   // [m/s] in child_frame_id
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();  // [rad/s] in child_frame_id
};
// Throws MessageError for a cut-off message or an orientation that is not a unit quaternion to within 1e-3 (it is
// then normalized); a non-finite position or orientation is returned as it is (the caller decides).
Odometry decodeOdometry(const std::uint8_t* data, std::size_t size);

// sensor_msgs/Imu -> ImuSample at the header stamp. The orientation is kept only when the driver provides one
// (orientation_covariance[0] != -1, REP 145) and it is a unit quaternion to within 1e-2 (drivers without an
// orientation often send zeros); it is then normalized. Non-finite rates or accelerations are returned as they
// are (the bag reader drops such a sample with a warning).
ImuSample decodeImu(const std::uint8_t* data, std::size_t size);

// sensor_msgs/Image (mono8, 8UC1, bgr8, rgb8, 8UC3, bgra8, rgba8) -> CameraFrame at the header stamp; colour is
// converted to BGR, row padding (step) removed. Other encodings (mono16, bayer...) are rejected.
CameraFrame decodeImage(const std::uint8_t* data, std::size_t size);

// sensor_msgs/CompressedImage (jpeg, png) decoded with OpenCV -> mono8 or BGR.
CameraFrame decodeCompressedImage(const std::uint8_t* data, std::size_t size);

}  // namespace drover::io::ros
