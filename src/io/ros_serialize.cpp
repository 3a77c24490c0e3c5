// ROS1 message serializers (io/ros_serialize.hpp); field order as in the definitions of
// io/ros_message_definitions.cpp.
#include "io/ros_serialize.hpp"

#include <bit>
#include <cmath>
#include <stdexcept>

namespace drover::io::ros {
namespace {

static_assert(std::endian::native == std::endian::little, "ROS1 messages are little-endian");

constexpr Time kMaxStamp = (Time{1} << 32) * kNanosPerSecond;

// sensor_msgs/PointField datatypes.
constexpr std::uint8_t kUint16 = 4, kFloat32 = 7;

void writeVector3(WireWriter& out, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) out.put(v[i]);
}

void writeCovariance(WireWriter& out, int n, double diagonal) {
  const int side = n == 9 ? 3 : 6;
  for (int i = 0; i < n; ++i) out.put(i % (side + 1) == 0 ? diagonal : 0.0);
}

void writeField(WireWriter& out, std::string_view name, std::uint32_t offset, std::uint8_t datatype) {
  out.string(name);
  out.put(offset);
  out.put(datatype);
  out.put(std::uint32_t{1});  // count
}

}  // namespace

void WireWriter::string(std::string_view s) {
  put(static_cast<std::uint32_t>(s.size()));
  out_.append(s);
}

void writeHeader(WireWriter& out, std::uint32_t seq, Time stamp, std::string_view frame_id) {
  if (stamp < 0 || stamp >= kMaxStamp)
    throw std::invalid_argument("ROS message stamp " + std::to_string(stamp) + " ns is outside 0 .. 2^32 s");
  out.put(seq);
  out.put(static_cast<std::uint32_t>(stamp / kNanosPerSecond));
  out.put(static_cast<std::uint32_t>(stamp % kNanosPerSecond));
  out.string(frame_id);
}

std::string serializePointCloud2(const LidarScan& scan, std::uint32_t seq, std::string_view frame_id) {
  const auto n = static_cast<std::uint32_t>(scan.points.size());
  WireWriter out;
  out.buffer().reserve(200 + static_cast<std::size_t>(n) * kVelodynePointStep);
  writeHeader(out, seq, scan.t, frame_id);
  out.put(std::uint32_t{1});  // height
  out.put(n);                 // width
  out.put(std::uint32_t{6});  // fields
  writeField(out, "x", 0, kFloat32);
  writeField(out, "y", 4, kFloat32);
  writeField(out, "z", 8, kFloat32);
  writeField(out, "intensity", 12, kFloat32);
  writeField(out, "ring", 16, kUint16);
  writeField(out, "time", 18, kFloat32);
  out.put(std::uint8_t{0});  // is_bigendian
  out.put(kVelodynePointStep);
  out.put(n * kVelodynePointStep);  // row_step
  out.put(n * kVelodynePointStep);  // data length
  for (std::uint32_t i = 0; i < n; ++i) {
    const LidarPoint& p = scan.points[i];
    const float time = scan.has_time ? p.time_offset : 0.0f;
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.intensity) ||
        !std::isfinite(time))
      throw std::invalid_argument("point cloud at " + std::to_string(scan.t) + " ns: point " + std::to_string(i) +
                                  " is not finite");
    out.put(p.x);
    out.put(p.y);
    out.put(p.z);
    out.put(p.intensity);
    out.put(p.ring);
    out.put(time);
  }
  out.put(std::uint8_t{1});  // is_dense
  return out.take();
}

std::string serializeImu(const ImuSample& s, std::uint32_t seq, std::string_view frame_id,
                         const ImuVariances& variances) {
  WireWriter out;
  writeHeader(out, seq, s.t, frame_id);
  const Eigen::Quaterniond q = s.q_world_imu.value_or(Eigen::Quaterniond(0, 0, 0, 0));
  for (double v : {q.x(), q.y(), q.z(), q.w()}) out.put(v);
  if (s.q_world_imu) writeCovariance(out, 9, 0.0);
  else writeCovariance(out, 9, -1.0);  // REP 145: element 0 = -1 marks "no orientation"; the rest unused
  writeVector3(out, s.omega_imu);
  writeCovariance(out, 9, variances.gyro);
  writeVector3(out, s.acc_imu);
  writeCovariance(out, 9, variances.accel);
  return out.take();
}

std::string serializeImage(const CameraFrame& frame, std::uint32_t seq, std::string_view frame_id) {
  const Image& img = frame.image;
  if (img.channels != 1 && img.channels != 3)
    throw std::invalid_argument("image with " + std::to_string(img.channels) + " channels: only mono8 and bgr8");
  const std::size_t size = static_cast<std::size_t>(img.width) * img.height * img.channels;
  if (img.width <= 0 || img.height <= 0 || img.data.size() != size)
    throw std::invalid_argument("image of " + std::to_string(img.width) + "x" + std::to_string(img.height) + "x" +
                                std::to_string(img.channels) + " holds " + std::to_string(img.data.size()) +
                                " bytes");
  WireWriter out;
  out.buffer().reserve(100 + size);
  writeHeader(out, seq, frame.t, frame_id);
  out.put(static_cast<std::uint32_t>(img.height));
  out.put(static_cast<std::uint32_t>(img.width));
  out.string(img.channels == 1 ? "mono8" : "bgr8");
  out.put(std::uint8_t{0});  // is_bigendian
  out.put(static_cast<std::uint32_t>(img.width * img.channels));  // step
  out.put(static_cast<std::uint32_t>(size));
  out.bytes(img.data.data(), size);
  return out.take();
}

std::string serializeOdometry(const Odometry& o, std::uint32_t seq) {
  WireWriter out;
  writeHeader(out, seq, o.t, o.frame_id);
  out.string(o.child_frame_id);
  writeVector3(out, o.T_frame_child.translation());
  const Eigen::Quaterniond q(o.T_frame_child.rotation());
  for (double v : {q.x(), q.y(), q.z(), q.w()}) out.put(v);
  writeCovariance(out, 36, 0.0);
  writeVector3(out, o.linear);
  writeVector3(out, o.angular);
  writeCovariance(out, 36, 0.0);
  return out.take();
}

}  // namespace drover::io::ros
