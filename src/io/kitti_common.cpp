#include "io/kitti_common.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/error.hpp"
#include "io/image_file_io.hpp"
#include "io/text_parsing.hpp"

namespace drover::io {

namespace {
LidarScan emptyScan(Time t, Time t_end) {
  LidarScan scan;
  scan.t = t;
  scan.t_end = t_end;
  scan.has_time = false;  // KITTI scans carry neither per-point time nor ring
  scan.has_ring = false;
  return scan;
}
}  // namespace

LidarScan readKittiBin(const std::string& path, Time t, Time t_end) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "", "cannot open velodyne scan: " + ec.message());
  if (bytes % 16 != 0)
    fail(path, "", "size " + std::to_string(bytes) + " bytes is not a multiple of 16 (float32 x, y, z, reflectance)");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "", "cannot open velodyne scan");
  const std::size_t n = bytes / 16;
  LidarScan scan = emptyScan(t, t_end);
  scan.points.resize(n);
  std::size_t kept = 0;
  // Converted in 64 KiB chunks: no scan-sized temporary to allocate, zero and fault in for every scan.
  constexpr std::size_t kChunkPoints = 4096;
  std::vector<std::uint32_t> chunk(4 * kChunkPoints);  // IEEE-754 float32 bit patterns
  for (std::size_t done = 0; done < n;) {
    const std::size_t m = std::min(kChunkPoints, n - done);
    in.read(reinterpret_cast<char*>(chunk.data()), static_cast<std::streamsize>(16 * m));
    if (static_cast<std::size_t>(in.gcount()) != 16 * m)
      fail(path, "point " + std::to_string(done + static_cast<std::size_t>(in.gcount()) / 16), "short read");
    // NaN and inf are the values whose exponent bits are all ones; an integer max over the exponents
    // vectorises, so the check is nearly free. Points are tested one by one only in a chunk that has one.
    constexpr std::uint32_t kExponent = 0x7f800000u;
    std::uint32_t max_exponent = 0;
    for (std::size_t k = 0; k < 4 * m; ++k) max_exponent = std::max(max_exponent, chunk[k] & kExponent);
    const bool check = max_exponent == kExponent;
    for (std::size_t i = 0; i < m; ++i) {
      const std::uint32_t* r = &chunk[4 * i];
      // A lidar's missing return: dropped and counted, as the README promises, rather than failing the scan.
      if (check && ((r[0] & kExponent) == kExponent || (r[1] & kExponent) == kExponent ||
                    (r[2] & kExponent) == kExponent || (r[3] & kExponent) == kExponent)) {
        ++scan.dropped_nonfinite;
        continue;
      }
      LidarPoint& p = scan.points[kept++];
      p.x = std::bit_cast<float>(r[0]);
      p.y = std::bit_cast<float>(r[1]);
      p.z = std::bit_cast<float>(r[2]);
      p.intensity = std::bit_cast<float>(r[3]);
    }
    done += m;
  }
  scan.points.resize(kept);
  return scan;
}

namespace {
// True when the token is NaN or inf as from_chars reads it ("nan", "-inf", "infinity"): a missing return.
bool nonFiniteToken(std::string_view token) {
  double v = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  return ec == std::errc() && ptr == token.data() + token.size() && !std::isfinite(v);
}
}  // namespace

LidarScan readKittiScanText(const std::string& path, Time t, Time t_end) {
  LidarScan scan = emptyScan(t, t_end);
  for (const auto& line : readDataLines(path, "#")) {
    const std::string record = lineRecord(line.number);
    const auto f = splitWhitespace(line.text);
    requireColumns(f, 4, path, record);
    if (std::any_of(f.begin(), f.end(), nonFiniteToken)) {
      ++scan.dropped_nonfinite;
      continue;
    }
    const auto v = parseDoubles(f, 0, 4, path, record);
    // Beyond float32's range the value would become inf: dropped as one.
    if (std::any_of(v.begin(), v.end(), [](double x) { return std::abs(x) > std::numeric_limits<float>::max(); })) {
      ++scan.dropped_nonfinite;
      continue;
    }
    LidarPoint p;
    p.x = static_cast<float>(v[0]);
    p.y = static_cast<float>(v[1]);
    p.z = static_cast<float>(v[2]);
    p.intensity = static_cast<float>(v[3]);
    scan.points.push_back(p);
  }
  return scan;
}

Image readImageFile(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) fail(path, "", "image file is missing");
  cv::Mat mat = decodeImageFile(path);
  if (mat.depth() != CV_8U) fail(path, "", "image is not 8-bit");
  if (mat.channels() == 4) cv::cvtColor(mat, mat, cv::COLOR_BGRA2BGR);
  if (mat.channels() != 1 && mat.channels() != 3)
    fail(path, "", "unsupported channel count " + std::to_string(mat.channels()));
  if (!mat.isContinuous()) mat = mat.clone();
  Image image;
  image.width = mat.cols;
  image.height = mat.rows;
  image.channels = mat.channels();
  image.data.assign(mat.data, mat.data + mat.total() * mat.elemSize());
  return image;
}

std::pair<int, int> pngSize(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char h[24] = {};
  if (!in.read(reinterpret_cast<char*>(h), sizeof(h))) return {0, 0};
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (std::memcmp(h, kSignature, 8) != 0 || std::memcmp(h + 12, "IHDR", 4) != 0) return {0, 0};
  const auto be32 = [&](int o) { return (h[o] << 24) | (h[o + 1] << 16) | (h[o + 2] << 8) | h[o + 3]; };
  return {be32(16), be32(20)};
}

namespace {
// All fields numbers? (from_chars: no exceptions for the expected "calib_time: 09-Jan-2012" lines.)
bool allNumbers(const std::vector<std::string_view>& fields, std::vector<double>& out) {
  out.clear();
  for (auto f : fields) {
    if (!f.empty() && f.front() == '+') f.remove_prefix(1);
    double v = 0;
    const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
    if (f.empty() || ec != std::errc() || ptr != f.data() + f.size()) return false;
    out.push_back(v);
  }
  return true;
}
}  // namespace

KittiCalibFile::KittiCalibFile(std::string path) : path_(std::move(path)) {
  for (const auto& line : readDataLines(path_, "#")) {
    const std::string record = lineRecord(line.number);
    const auto colon = line.text.find(':');
    if (colon == std::string::npos) fail(path_, record, "expected 'key: values'");
    const std::string key(trim(std::string_view(line.text).substr(0, colon)));
    const auto fields = splitWhitespace(std::string_view(line.text).substr(colon + 1));
    std::vector<double> values;
    if (!allNumbers(fields, values)) {  // dates and names, not calibration numbers (unless a number is asked for)
      std::string shown = fields.empty() ? std::string() : std::string(fields[values.size()]);
      if (shown.size() > 20) shown = shown.substr(0, 20) + "...";
      text_.emplace(key, shown);
      lines_.emplace(key, line.number);
      continue;
    }
    for (double v : values)
      if (!std::isfinite(v)) fail(path_, record, "non-finite value in '" + key + "'");
    if (!numbers_.emplace(key, std::move(values)).second) fail(path_, record, "duplicate key '" + key + "'");
    lines_[key] = line.number;
  }
}

const std::vector<double>& KittiCalibFile::get(const std::string& key, std::size_t count) const {
  const auto it = numbers_.find(key);
  if (const auto t = text_.find(key); it == numbers_.end() && t != text_.end())
    fail(path_, lineRecord(lines_.at(key)), "key '" + key + "' has a value that is not a number: '" + t->second + "'");
  if (it == numbers_.end()) fail(path_, "", "missing key '" + key + "'");
  if (it->second.size() != count)
    fail(path_, lineRecord(lines_.at(key)),
         "key '" + key + "' has " + std::to_string(it->second.size()) + " values, expected " + std::to_string(count));
  return it->second;
}

Eigen::Matrix<double, 3, 4> KittiCalibFile::matrix34(const std::string& key) const {
  const auto& v = get(key, 12);
  return Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>>(v.data());
}

Eigen::Matrix3d KittiCalibFile::matrix33(const std::string& key) const {
  const auto& v = get(key, 9);
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(v.data());
}

void KittiCalibFile::requireFocalLengths(const std::string& key, double fx, double fy) const {
  if (!(fx > 0) || !(fy > 0))
    fail(path_, lineRecord(lines_.at(key)),
         "key '" + key + "': focal lengths must be > 0 px, got fx " + formatDouble(fx) + ", fy " + formatDouble(fy));
}

Eigen::Matrix<double, 3, 4> KittiCalibFile::projection34(const std::string& key) const {
  const Eigen::Matrix<double, 3, 4> P = matrix34(key);
  requireFocalLengths(key, P(0, 0), P(1, 1));
  return P;
}

Eigen::Matrix3d KittiCalibFile::intrinsics33(const std::string& key) const {
  const Eigen::Matrix3d K = matrix33(key);
  requireFocalLengths(key, K(0, 0), K(1, 1));
  return K;
}

Eigen::Isometry3d KittiCalibFile::rigid34(const std::string& key) const {
  const Eigen::Matrix<double, 3, 4> M = matrix34(key);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = checkedRotation(M.leftCols<3>(), path_, "key '" + key + "'");
  T.translation() = M.col(3);
  return T;
}

Eigen::Isometry3d KittiCalibFile::rigidRT(const std::string& r_key, const std::string& t_key) const {
  const auto& t = get(t_key, 3);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = checkedRotation(matrix33(r_key), path_, "key '" + r_key + "'");
  T.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return T;
}

Eigen::Isometry3d rectifiedCameraOffset(const Eigen::Matrix<double, 3, 4>& P) {
  const Eigen::Matrix3d K = P.leftCols<3>();
  Eigen::Isometry3d T_ref_cam = Eigen::Isometry3d::Identity();
  T_ref_cam.translation() = -K.inverse() * P.col(3);
  return T_ref_cam;
}

}  // namespace drover::io
