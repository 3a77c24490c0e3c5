#include "vio/vio_config.hpp"

#include <cmath>
#include <string>

namespace drover::vio {

const char* toString(DepthMode mode) {
  switch (mode) {
    case DepthMode::kFixed:
      return "fixed";
    case DepthMode::kFactor:
      return "factor";
    case DepthMode::kOff:
      break;
  }
  return "off";
}

const char* toString(InitMode mode) {
  switch (mode) {
    case InitMode::kLis:
      return "lis";
    case InitMode::kVisual:
      return "visual";
    case InitMode::kAuto:
      break;
  }
  return "auto";
}

namespace {
bool positive(double x) { return std::isfinite(x) && x > 0; }
bool nonNegative(double x) { return std::isfinite(x) && x >= 0; }
}  // namespace

std::string VioConfig::validate() const {
  if (window < 3 || window > 50) return "window must be in [3, 50] frames";
  if (!positive(min_parallax_px)) return "min_parallax_px must be > 0";
  if (min_tracked_for_parallax < 0) return "min_tracked_for_parallax must be >= 0";
  if (!positive(focal_px)) return "focal_px must be > 0";
  if (!nonNegative(max_keyframe_interval_s)) return "max_keyframe_interval_s must be >= 0 (0: off)";
  if (!(seed_max_median_px >= 0)) return "seed_max_median_px must be >= 0 (0: no check)";
  if (seed_min_observations < 1) return "seed_min_observations must be >= 1";
  if (!positive(sigma_px)) return "sigma_px must be > 0";
  if (!nonNegative(ground_height_m)) return "ground_height_m must be >= 0 (0: off)";
  if (!positive(ground_sigma_m) || !nonNegative(ground_slope_sigma_rad))
    return "ground_sigma_m must be > 0 and ground_slope_sigma_rad >= 0";
  if (!positive(ground_gate_rel) || !(ground_gate_rel < 1) || !positive(ground_max_range_m))
    return "ground_gate_rel must be in (0, 1) and ground_max_range_m > 0";
  if (!nonNegative(ground_check_every_s) || ground_check_min_points < 3 || !positive(ground_check_cluster_rel) ||
      !(ground_check_cluster_rel < 0.5))
    return "ground_check_every_s must be >= 0, ground_check_min_points >= 3, ground_check_cluster_rel in (0, 0.5)";
  if (!positive(robust_px)) return "robust_px must be > 0";
  if (!positive(outlier_px)) return "outlier_px must be > 0";
  if (min_observations < 2) return "min_observations must be >= 2";
  if (max_features < 1) return "max_features must be >= 1";
  if (!positive(depth_sigma_m) || !nonNegative(depth_sigma_rel) || !nonNegative(depth_sigma_spread))
    return "depth_sigma_m must be > 0, depth_sigma_rel and depth_sigma_spread >= 0";
  if (max_iterations < 1) return "max_iterations must be >= 1";
  if (!nonNegative(max_solver_ms)) return "max_solver_ms must be >= 0";
  if (!positive(max_time_offset_s)) return "max_time_offset_s must be > 0";
  if (!positive(time_offset_sigma_s)) return "time_offset_sigma_s must be > 0";
  if (!positive(init_min_parallax_px)) return "init_min_parallax_px must be > 0";
  for (double sigma : {init_sigma_position_m, lis_sigma_rotation_rad, lis_sigma_velocity, lis_sigma_gyro_bias,
                       lis_sigma_acc_bias, align_sigma_rotation_rad, align_sigma_velocity, align_sigma_gyro_bias,
                       align_sigma_acc_bias})
    if (!positive(sigma)) return "the initialisation sigmas (init_sigma_*, lis_sigma_*, align_sigma_*) must be > 0";
  if (!nonNegative(lis_bias_prior_sigma_gyro) || !nonNegative(lis_bias_prior_sigma_acc) ||
      (lis_bias_prior_sigma_gyro > 0) != (lis_bias_prior_sigma_acc > 0))
    return "lis_bias_prior_sigma_gyro and lis_bias_prior_sigma_acc must be >= 0, and both 0 (off) or both > 0";
  if (!nonNegative(acc_bias_prior_sigma)) return "acc_bias_prior_sigma must be >= 0 (0: off)";
  if (!nonNegative(init_min_acc_excitation)) return "init_min_acc_excitation must be >= 0";
  if (!positive(init_max_scale_rel_sigma)) return "init_max_scale_rel_sigma must be > 0";
  if (!nonNegative(scale_check_span_s)) return "scale_check_span_s must be >= 0";
  if (!positive(scale_check_every_s)) return "scale_check_every_s must be > 0";
  if (!positive(scale_check_max_rel_sigma)) return "scale_check_max_rel_sigma must be > 0";
  if (!nonNegative(scale_check_min_change)) return "scale_check_min_change must be >= 0";
  if (!(scale_check_max_change > 1)) return "scale_check_max_change must be > 1";
  if (!nonNegative(scale_check_bias_sigma)) return "scale_check_bias_sigma must be >= 0";
  if (min_tracked < 0) return "min_tracked must be >= 0";
  if (!nonNegative(coast_max_s)) return "coast_max_s must be >= 0 (0: no coasting)";
  if (!positive(max_imu_gap_s)) return "max_imu_gap_s must be > 0";
  if (!positive(max_acc_bias) || !positive(max_gyro_bias) || !positive(max_jump_m) || !positive(max_height_jump_m) ||
      !positive(max_turn_deg) || !positive(max_speed))
    return "the failure thresholds (max_acc_bias, max_gyro_bias, max_jump_m, max_height_jump_m, max_turn_deg, "
           "max_speed) must be > 0";
  return {};
}

}  // namespace drover::vio
