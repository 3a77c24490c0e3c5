#include "io/ros_messages.hpp"

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/image_file_io.hpp"

namespace drover::io::ros {
namespace {

Eigen::Vector3d readVector3(WireReader& in) {
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = in.get<double>();
  return v;
}

void finishImage(CameraFrame& f, const cv::Mat& m) {
  f.image.width = m.cols;
  f.image.height = m.rows;
  f.image.channels = m.channels();
  f.image.data.resize(m.total() * m.elemSize());
  const std::size_t row_bytes = static_cast<std::size_t>(m.cols) * m.elemSize();
  for (int r = 0; r < m.rows; ++r) std::memcpy(f.image.data.data() + r * row_bytes, m.ptr(r), row_bytes);
}

}  // namespace

Header readHeader(WireReader& in) {
  Header h;
  h.seq = in.get<std::uint32_t>();
  const auto sec = in.get<std::uint32_t>(), nsec = in.get<std::uint32_t>();
  if (nsec >= kNanosPerSecond) throw MessageError("header stamp has nsec = " + std::to_string(nsec) + " >= 1e9");
  h.stamp = static_cast<Time>(sec) * kNanosPerSecond + nsec;
  h.frame_id = in.string();
  return h;
}

Odometry decodeOdometry(const std::uint8_t* data, std::size_t size) {
  WireReader in(data, size);
  Odometry o;
  const Header h = readHeader(in);
  o.t = h.stamp;
  o.frame_id = h.frame_id;
  o.child_frame_id = in.string();
  const Eigen::Vector3d p = readVector3(in);
  const double qx = in.get<double>(), qy = in.get<double>(), qz = in.get<double>(), qw = in.get<double>();
  in.take(36 * sizeof(double));  // pose covariance
  o.linear = readVector3(in);
  o.angular = readVector3(in);
  in.take(36 * sizeof(double));  // twist covariance
  Eigen::Quaterniond q(qw, qx, qy, qz);
  if (q.coeffs().allFinite()) {
    if (std::abs(q.norm() - 1.0) > 1e-3)
      throw MessageError("pose orientation is not a unit quaternion (norm " + std::to_string(q.norm()) + ")");
    q.normalize();
  }
  o.T_frame_child.linear() = q.toRotationMatrix();
  o.T_frame_child.translation() = p;
  return o;
}

ImuSample decodeImu(const std::uint8_t* data, std::size_t size) {
  WireReader in(data, size);
  ImuSample s;
  s.t = readHeader(in).stamp;
  const double qx = in.get<double>(), qy = in.get<double>(), qz = in.get<double>(), qw = in.get<double>();
  double orientation_cov[9];
  for (double& c : orientation_cov) c = in.get<double>();
  s.omega_imu = readVector3(in);
  in.take(9 * sizeof(double));  // angular_velocity_covariance
  s.acc_imu = readVector3(in);
  in.take(9 * sizeof(double));  // linear_acceleration_covariance
  const Eigen::Quaterniond q(qw, qx, qy, qz);
  // REP 145: covariance[0] == -1 marks "no orientation estimate".
  if (orientation_cov[0] != -1.0 && q.coeffs().allFinite() && std::abs(q.norm() - 1.0) < 1e-2)
    s.q_world_imu = q.normalized();
  return s;
}

CameraFrame decodeImage(const std::uint8_t* data, std::size_t size) {
  WireReader in(data, size);
  CameraFrame f;
  f.t = readHeader(in).stamp;
  const auto height = in.get<std::uint32_t>(), width = in.get<std::uint32_t>();
  const std::string encoding = in.string();
  in.get<std::uint8_t>();  // is_bigendian: irrelevant for 8-bit channels
  const auto step = in.get<std::uint32_t>();
  const auto n = in.get<std::uint32_t>();
  const std::uint8_t* pixels = in.take(n);

  int channels = 0;
  int conversion = -1;  // cv::ColorConversionCodes, -1 = copy as is
  if (encoding == "mono8" || encoding == "8UC1") {
    channels = 1;
  } else if (encoding == "bgr8" || encoding == "8UC3") {
    channels = 3;
  } else if (encoding == "rgb8") {
    channels = 3, conversion = cv::COLOR_RGB2BGR;
  } else if (encoding == "bgra8" || encoding == "8UC4") {
    channels = 4, conversion = cv::COLOR_BGRA2BGR;
  } else if (encoding == "rgba8") {
    channels = 4, conversion = cv::COLOR_RGBA2BGR;
  } else {
    throw MessageError("unsupported image encoding '" + encoding +
                       "' (supported: mono8, bgr8, rgb8, bgra8, rgba8; convert 16-bit or Bayer images first)");
  }
  if (width == 0 || height == 0 || width > 65535 || height > 65535)
    throw MessageError("implausible image size " + std::to_string(width) + "x" + std::to_string(height));
  if (step < static_cast<std::uint64_t>(width) * channels)
    throw MessageError("image step " + std::to_string(step) + " is smaller than width * channels");
  if (static_cast<std::uint64_t>(step) * height > n)
    throw MessageError("image data has " + std::to_string(n) + " bytes, step * height needs " +
                       std::to_string(static_cast<std::uint64_t>(step) * height));
  const cv::Mat view(static_cast<int>(height), static_cast<int>(width), CV_8UC(channels),
                     const_cast<std::uint8_t*>(pixels), step);
  if (conversion < 0) {
    finishImage(f, view);
  } else {
    cv::Mat bgr;
    cv::cvtColor(view, bgr, conversion);
    finishImage(f, bgr);
  }
  return f;
}

CameraFrame decodeCompressedImage(const std::uint8_t* data, std::size_t size) {
  WireReader in(data, size);
  CameraFrame f;
  f.t = readHeader(in).stamp;
  const std::string format = in.string();
  const auto n = in.get<std::uint32_t>();
  const std::uint8_t* bytes = in.take(n);
  if (format.find("compressedDepth") != std::string::npos)
    throw MessageError("compressed depth images ('" + format + "') are not supported");
  if (const std::string problem = imageHeaderProblem(bytes, n); !problem.empty())
    throw MessageError("compressed image ('" + format + "'): " + problem);
  const cv::Mat buffer(1, static_cast<int>(n), CV_8UC1, const_cast<std::uint8_t*>(bytes));
  cv::Mat m;
  try {
    m = cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw MessageError("cannot decode compressed image ('" + format + "'): " + e.err);
  }
  if (m.empty()) throw MessageError("cannot decode compressed image ('" + format + "')");
  if (m.depth() != CV_8U) throw MessageError("compressed image is not 8-bit ('" + format + "')");
  // compressed_image_transport encodes what it was given; "compressed rgb8" means the codec holds RGB.
  const bool rgb = format.find("compressed rgb") != std::string::npos;
  if (m.channels() == 4) {
    cv::cvtColor(m, m, rgb ? cv::COLOR_RGBA2BGR : cv::COLOR_BGRA2BGR);
  } else if (m.channels() == 3 && rgb) {
    cv::cvtColor(m, m, cv::COLOR_RGB2BGR);
  } else if (m.channels() != 1 && m.channels() != 3) {
    throw MessageError("compressed image has " + std::to_string(m.channels()) + " channels");
  }
  finishImage(f, m);
  return f;
}

}  // namespace drover::io::ros
