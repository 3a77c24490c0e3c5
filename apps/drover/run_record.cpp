#include "apps/drover/run_record.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <numeric>

#include "io/error.hpp"
#include "io/trajectory_io.hpp"

namespace drover::cli {
namespace {

using Json = nlohmann::json;
constexpr double kLowest = 1e-4, kHighest = 1e7, kRatio = 1.01;  // the histogram's range and bin ratio

Json vectorJson(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json vectorJson(const Eigen::Matrix<double, 6, 1>& v) {
  Json out = Json::array();
  for (int i = 0; i < 6; ++i) out.push_back(std::round(v(i) * 1e4) / 1e4);  // 4 decimals: a direction, not a value
  return out;
}

}  // namespace

std::size_t BoundedQuantiles::bin(double v) {
  if (!(v > kLowest)) return 0;
  const double b = std::log(std::min(v, kHighest) / kLowest) / std::log(kRatio);
  return static_cast<std::size_t>(b);
}

double BoundedQuantiles::binValue(std::size_t b) {  // the bin's geometric middle
  return kLowest * std::pow(kRatio, static_cast<double>(b) + 0.5);
}

void BoundedQuantiles::add(double v) {
  ++count_;
  sum_ += v;
  max_ = count_ == 1 ? v : std::max(max_, v);
  if (bins_.empty() && exact_.size() < kExact) {
    exact_.push_back(v);
    return;
  }
  if (bins_.empty()) {  // the kExact + 1-th value: from now on, bins only
    bins_.assign(bin(kHighest) + 1, 0);
    for (double x : exact_) ++bins_[bin(x)];
    exact_.clear();
    exact_.shrink_to_fit();
  }
  ++bins_[bin(v)];
}

double BoundedQuantiles::quantile(double q) const {
  if (count_ == 0) return 0;
  const std::size_t rank = static_cast<std::size_t>(std::lround(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_ - 1)));
  if (bins_.empty()) {
    std::vector<double> v = exact_;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(rank), v.end());
    return v[rank];
  }
  std::size_t seen = 0;
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    seen += bins_[b];
    if (seen > rank) return std::min(binValue(b), max_);
  }
  return max_;
}

Json BoundedQuantiles::percentiles() const {
  if (count_ == 0) return Json{{"p50", nullptr}, {"p95", nullptr}, {"max", nullptr}, {"count", 0}};
  return Json{{"p50", quantile(0.50)}, {"p95", quantile(0.95)}, {"max", max_}, {"count", count_}};
}

void JsonLines::streamTo(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw io::IoError(path, "", std::string("cannot open for writing: ") + std::strerror(errno));
  file_.reset(f, [](std::FILE* p) { std::fclose(p); });
  path_ = path;
}

void JsonLines::keepNewest(std::size_t n) { keep_ = n; }

Json SweepLog::line(const pipeline::ScanOutcome& s) {
  Json j = {{"t", toSeconds(s.t)},
            {"status", s.match_status},
            {"iterations", s.iterations},
            {"fitness_m", s.fitness},
            {"edge_inliers", s.edge_inliers},
            {"plane_inliers", s.plane_inliers},
            {"points", s.points},
            {"edges", s.edges},
            {"planes", s.planes},
            {"keyframe", s.keyframe},
            {"degenerate", s.degenerate_count},
            {"min_eigenvalue", std::round(s.min_eigenvalue * 10) / 10},
            {"imu", s.imu_used},
            {"reset", s.reset},
            {"total_ms", s.ms.total}};
  // Each degenerate direction of the match: a unit vector in the lidar's tangent [rho (m); phi (rad)].
  if (!s.degenerate_directions.empty()) {
    Json dirs = Json::array();
    for (const auto& d : s.degenerate_directions) dirs.push_back(vectorJson(d));
    j["degenerate_directions"] = dirs;
  }
  // With a VIS: whether its motion was the matcher's guess and a smoother factor, or why it was not used.
  if (s.vis_guess) j["vis_guess"] = true;
  if (s.vis_factor) j["vis_factor"] = true;
  if (!s.vis_unused.empty()) j["vis_unused"] = s.vis_unused;
  if (!s.vis_reset.empty()) j["vis_reset"] = s.vis_reset;
  if (!s.warning.empty()) j["warning"] = s.warning;
  if (s.has_imu_state) {
    j["v_world"] = vectorJson(s.v_world);      // [m/s]
    j["gyro_bias"] = vectorJson(s.gyro_bias);  // [rad/s], IMU frame
    j["acc_bias"] = vectorJson(s.acc_bias);    // [m/s^2], IMU frame
  }
  return j;
}

void JsonLines::add(const Json& line) {
  ++lines_;
  if (!file_ && keep_ == 0) return;
  const std::string text = line.dump() + "\n";
  if (file_) {
    if (std::fputs(text.c_str(), file_.get()) < 0)
      throw io::IoError(path_, record_ + " " + std::to_string(lines_), "write failed");
  } else {
    newest_.push_back(text);
    if (newest_.size() > keep_) newest_.pop_front();
  }
}

void JsonLines::finish(const std::string& path) {
  if (file_) {
    if (std::fflush(file_.get()) != 0 || std::ferror(file_.get()) != 0)
      throw io::IoError(path_, "", "write failed (disk full?)");
    file_.reset();
    return;
  }
  std::string all;
  for (const std::string& l : newest_) all += l;
  io::writeFileAtomically(path, all);
}

ImuRateFile::ImuRateFile(const std::string& path, const Eigen::Isometry3d& T_imu_body)
    : stream_(path), T_imu_body_(T_imu_body) {}

void ImuRateFile::add(Time t, const Eigen::Isometry3d& T_world_imu) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (summary_.poses > 0 && t <= summary_.last) return;
  stream_.add({t, T_world_imu * T_imu_body_});
  if (summary_.poses++ == 0) summary_.first = t;
  summary_.last = t;
}

ImuRateFile::Summary ImuRateFile::copyTo(const std::string& dest) {
  namespace fs = std::filesystem;
  std::lock_guard<std::mutex> lock(mutex_);
  stream_.flush();
  std::error_code e;
  if (!fs::equivalent(stream_.path(), dest, e)) {
    fs::copy_file(stream_.path(), dest, fs::copy_options::overwrite_existing, e);
    if (e) throw io::IoError(dest, "", "cannot copy the IMU-rate odometry from " + stream_.path() + ": " + e.message());
  }
  return summary_;
}

const std::array<const char*, 8>& RunRecord::stageNames() {
  static const std::array<const char*, 8> names = {"preprocess", "deskew", "features", "map",
                                                   "match",      "smoother", "loop",   "total"};
  return names;
}

void RunRecord::add(const pipeline::ScanOutcome& s) {
  if (sweeps == 0) first_t = s.t;
  last_t = s.t;
  ++sweeps;
  const double values[] = {s.ms.preprocess, s.ms.deskew, s.ms.features, s.ms.map,
                           s.ms.match,      s.ms.smoother, s.ms.loop,   s.ms.total};
  for (std::size_t i = 0; i < stage_ms.size(); ++i) stage_ms[i].add(values[i]);
  log.add(s);
}

}  // namespace drover::cli
