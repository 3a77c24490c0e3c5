#include "lidar/deskew.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "geometry/se3.hpp"

namespace drover::lidar {
namespace {

// One motion sample, in float for the per-point work (the points are float).
struct PoseSample {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t = Eigen::Vector3f::Zero();
};

PoseSample sampleAt(const SweepMotion& motion, double time_offset, DeskewMode mode) {
  const Eigen::Isometry3d T = motion(time_offset);
  PoseSample s;
  if (mode == DeskewMode::kRotation || mode == DeskewMode::kFull) s.R = T.linear().cast<float>();
  if (mode == DeskewMode::kTranslation || mode == DeskewMode::kFull) s.t = T.translation().cast<float>();
  return s;
}

}  // namespace

SweepMotion constantVelocityMotion(const Eigen::Isometry3d& T_start_end, double period) {
  if (!std::isfinite(period) || period <= 0)
    throw std::invalid_argument("constantVelocityMotion: period must be finite and > 0, got " +
                                std::to_string(period));
  const geometry::Vector6d xi = geometry::logSE3(T_start_end);
  return [xi, period](double t) { return geometry::expSE3((t / period) * xi); };
}

std::string DeskewerConfig::validate() const {
  if (time_bins < 1 || time_bins > 100000)
    return "time_bins must be in [1, 100000], got " + std::to_string(time_bins);
  return {};
}

Deskewer::Deskewer(const DeskewerConfig& config) : config_(config) {
  const std::string error = config.validate();
  if (!error.empty()) throw std::invalid_argument("Deskewer: invalid config: " + error);
}

DeskewResult Deskewer::deskew(const LidarScan& scan, const SweepMotion& T_start_lidar) const {
  if (!scan.has_time)
    throw std::invalid_argument("Deskewer::deskew: the scan has no per-point times (has_time == false); "
                                "call inferTimes() first");
  if (!T_start_lidar) throw std::invalid_argument("Deskewer::deskew: empty motion function");
  DeskewResult result;
  result.scan = scan;
  if (scan.points.empty()) {
    result.status = DeskewStatus::kEmpty;
    return result;
  }
  if (config_.mode == DeskewMode::kNone) return result;

  float t_max = 0;
  for (const LidarPoint& p : scan.points)
    if (std::isfinite(p.time_offset)) t_max = std::max(t_max, p.time_offset);
  result.max_time_offset = t_max;
  const int bins = t_max > 0 ? config_.time_bins : 0;
  if (bins == 0) result.status = DeskewStatus::kNoTimeSpread;

  std::vector<PoseSample> samples(static_cast<std::size_t>(bins) + 1);
  for (int k = 0; k <= bins; ++k)
    samples[static_cast<std::size_t>(k)] =
        sampleAt(T_start_lidar, bins == 0 ? 0.0 : double(t_max) * k / bins, config_.mode);

  const float bins_per_second = bins == 0 ? 0.0f : static_cast<float>(bins) / t_max;
  for (LidarPoint& p : result.scan.points) {
    const float time = std::isfinite(p.time_offset) ? p.time_offset : 0.0f;  // a NaN time: treated as the start
    const float u = std::clamp(time * bins_per_second, 0.0f, static_cast<float>(bins));
    const int k = std::min(static_cast<int>(u), std::max(bins - 1, 0));
    const float a = u - static_cast<float>(k);
    const PoseSample& s0 = samples[static_cast<std::size_t>(k)];
    const PoseSample& s1 = samples[static_cast<std::size_t>(std::min(k + 1, bins))];
    const Eigen::Vector3f x(p.x, p.y, p.z);
    // Blend of the two neighbouring rigid motions applied to the point (exact at the samples).
    const Eigen::Vector3f q = (1.0f - a) * (s0.R * x + s0.t) + a * (s1.R * x + s1.t);
    p.x = q.x();
    p.y = q.y();
    p.z = q.z();
  }
  return result;
}

}  // namespace drover::lidar
