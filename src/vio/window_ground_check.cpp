// The window's scale checked against the ground below a wheeled robot (vio_config.hpp ground_check_*).
//
// A point on the ground lies the camera's height c below the camera (in the body's axes). In a window whose scale is
// s times the truth, every such point lies s c below it, so the points on the ground agree on one scale however far
// the window has gone, while the ground factors reach only the points within ground_gate_rel of the true height.
// Points on walls, boxes and the far scene imply scattered scales; the ground below a ground robot is the one
// surface many points share. This is the height-from-the-ground scale of monocular car odometry (e.g. Kitt et al.,
// "Monocular visual odometry using a planar road model", 2010) as a check, not a factor.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "vio/window_frame.hpp"

namespace drover::vio {

namespace {

struct GroundScales {
  std::vector<double> log_scales;  // sorted: log of the scale each candidate point implies
  int in_gate = 0;                 // candidates the ground factors hold (within ground_gate_rel of the height)
};

// The densest run of log scales no wider than 2 * half: its count and its median.
std::pair<std::size_t, double> densestCluster(const std::vector<double>& sorted, double half) {
  std::size_t best_n = 0, best_end = 0;
  for (std::size_t i = 0, j = 0; i < sorted.size(); ++i) {
    while (sorted[j] < sorted[i] - 2 * half) ++j;
    if (i - j + 1 > best_n) best_n = i - j + 1, best_end = i + 1;
  }
  if (best_n == 0) return {0, 0.0};
  return {best_n, sorted[best_end - best_n + best_n / 2]};
}

}  // namespace

void SlidingWindowEstimator::checkGroundScale(FrameResult& result) {
  if (!alone_ || !(config_.ground_height_m > 0) || !(config_.ground_check_every_s > 0)) return;
  if (result.t - last_ground_check_ < fromSeconds(config_.ground_check_every_s)) return;
  last_ground_check_ = result.t;
  const Eigen::Isometry3d T_ic = T_imu_cam();
  const double camera_height = config_.ground_height_m + T_ic.translation().z();  // [m] above the ground
  if (!(camera_height > 0)) return;
  const double max_change = config_.scale_check_max_change;
  const int newest = static_cast<int>(frames_.size()) - 1;
  GroundScales g;
  for (const auto& [id, f] : features_.features()) {
    if (!(f.depth > 0) || f.lidar_anchor || !features_.usable(f, newest, config_.min_observations)) continue;
    // The point from the anchor camera, in the anchor body's axes [m, window scale].
    const Eigen::Vector3d d = T_ic.linear() * (f.depth * f.obs.front().normalized.homogeneous());
    if (!(d.z() < 0)) continue;
    const double scale = -d.z() / camera_height;
    if (scale < 1 / max_change || scale > max_change) continue;
    // As far as the ground factors reach at the right scale; scales beyond scale_check_max_change are not asked.
    if (d.head<2>().norm() / scale > config_.ground_max_range_m) continue;
    if (std::abs(scale - 1) <= config_.ground_gate_rel) ++g.in_gate;
    g.log_scales.push_back(std::log(scale));
  }
  const int min_points = config_.ground_check_min_points;
  const auto no_proposal = [this] { pending_ground_scale_.reset(); };
  if (static_cast<int>(g.log_scales.size()) < min_points) return no_proposal();
  std::sort(g.log_scales.begin(), g.log_scales.end());
  const auto [n, log_scale] = densestCluster(g.log_scales, std::log1p(config_.ground_check_cluster_rel));
  if (static_cast<int>(n) < min_points || static_cast<int>(n) < 2 * g.in_gate) return no_proposal();
  if (std::abs(std::exp(log_scale) - 1) <= config_.ground_gate_rel) return no_proposal();  // the ground factors' job
  // Two checks in a row must agree: the points were solved a moment before, and a window that has just recovered by
  // itself still has them at the old scale for a frame or two (the farm's seed 2 at 328 s).
  const bool confirmed = pending_ground_scale_ &&
                         std::abs(*pending_ground_scale_ - log_scale) <= std::log1p(config_.ground_check_cluster_rel);
  pending_ground_scale_ = log_scale;
  if (!confirmed) return;
  pending_ground_scale_.reset();
  ScaleCheck check;
  check.ok = true;
  check.scale = std::exp(-log_scale);  // metric / window
  applyScale(check, config_.ground_check_cluster_rel);
  result.rescaled = true;
  result.event += (result.event.empty() ? "" : "; ") +
                  fmt::format("scale x{:.3f} from the ground: {} of {} points below the camera agree on it, {} within "
                              "the ground factors' gate",
                              check.scale, n, g.log_scales.size(), g.in_gate);
}

}  // namespace drover::vio
