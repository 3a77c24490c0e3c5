#include "eval/kitti_drift.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "eval/message.hpp"
#include "geometry/se3.hpp"

namespace drover::eval {

std::vector<double> trajectoryDistances(const std::vector<Eigen::Isometry3d>& poses) {
  std::vector<double> dist;
  dist.reserve(poses.size());
  if (poses.empty()) return dist;
  dist.push_back(0.0);
  for (std::size_t i = 1; i < poses.size(); ++i)
    dist.push_back(dist[i - 1] + (poses[i - 1].translation() - poses[i].translation()).norm());
  return dist;
}

long lastFrameFromSegmentLength(const std::vector<double>& dist, std::size_t first_frame, double len) {
  for (std::size_t i = first_frame; i < dist.size(); ++i)
    if (dist[i] > dist[first_frame] + len) return static_cast<long>(i);
  return -1;
}

namespace {

// The devkit's rotationError: the angle of E from its trace, clamped against rounding.
double rotationError(const Eigen::Isometry3d& E) {
  const double d = 0.5 * (E.linear().trace() - 1.0);
  return std::acos(std::clamp(d, -1.0, 1.0));
}

void validate(const std::vector<Eigen::Isometry3d>& gt, const std::vector<Eigen::Isometry3d>& est,
              const KittiDriftOptions& o) {
  if (gt.empty()) throw std::invalid_argument("KITTI drift: the ground truth has no poses");
  if (gt.size() != est.size())
    throw std::invalid_argument("KITTI drift matches poses by index and needs equal counts: ground truth has " +
                                std::to_string(gt.size()) + " poses, estimate " + std::to_string(est.size()));
  if (o.step_size == 0) throw std::invalid_argument("KITTI drift: step_size must be >= 1");
  if (o.lengths.empty()) throw std::invalid_argument("KITTI drift: no segment lengths");
  for (const double l : o.lengths)
    if (!(l > 0.0) || !std::isfinite(l))
      throw std::invalid_argument("KITTI drift: segment length must be > 0, got " + shortNumber(l));
}

}  // namespace

KittiDriftResult computeKittiDrift(const std::vector<Eigen::Isometry3d>& gt, const std::vector<Eigen::Isometry3d>& est,
                                   const KittiDriftOptions& options) {
  validate(gt, est, options);
  KittiDriftResult r;
  const std::vector<double> dist = trajectoryDistances(gt);
  r.path_length = dist.back();
  for (std::size_t first = 0; first < gt.size(); first += options.step_size) {
    for (const double len : options.lengths) {
      const long last = lastFrameFromSegmentLength(dist, first, len);
      if (last < 0) continue;
      const auto l = static_cast<std::size_t>(last);
      const Eigen::Isometry3d delta_gt = geometry::inverse(gt[first]) * gt[l];
      const Eigen::Isometry3d delta_est = geometry::inverse(est[first]) * est[l];
      const Eigen::Isometry3d E = geometry::inverse(delta_est) * delta_gt;
      r.segments.push_back({first, l, len, rotationError(E) / len, E.translation().norm() / len});
    }
  }
  if (r.segments.empty()) {
    const double shortest = *std::min_element(options.lengths.begin(), options.lengths.end());
    throw std::invalid_argument("KITTI drift: no segment fits: the ground-truth path is " +
                                shortNumber(r.path_length) + " m, the shortest segment length " +
                                shortNumber(shortest) + " m");
  }
  constexpr double kRadToDeg = 180.0 / std::numbers::pi;
  double t_sum = 0.0, r_sum = 0.0;
  for (const auto& s : r.segments) {
    t_sum += s.t_err;
    r_sum += s.r_err;
  }
  const double n = static_cast<double>(r.segments.size());
  r.t_err_percent = 100.0 * t_sum / n;
  r.r_err_deg_per_100m = r_sum / n * kRadToDeg * 100.0;
  for (const double len : options.lengths) {
    KittiLengthDrift d;
    d.length = len;
    double t = 0.0, rr = 0.0;
    for (const auto& s : r.segments)
      if (s.length == len) {
        t += s.t_err;
        rr += s.r_err;
        ++d.segments;
      }
    if (d.segments > 0) {
      d.t_err_percent = 100.0 * t / static_cast<double>(d.segments);
      d.r_err_deg_per_100m = rr / static_cast<double>(d.segments) * kRadToDeg * 100.0;
    }
    r.per_length.push_back(d);
  }
  return r;
}

}  // namespace drover::eval
