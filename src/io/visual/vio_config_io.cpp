#include "io/visual/vio_config_io.hpp"

#include <yaml-cpp/yaml.h>

#include "io/user_values.hpp"
#include "io/yaml_section.hpp"

namespace drover::io {
namespace {

vio::DepthMode parseDepthMode(const std::string& s) {  // already checked by bindChoice
  if (s == "factor") return vio::DepthMode::kFactor;
  if (s == "off") return vio::DepthMode::kOff;
  return vio::DepthMode::kFixed;
}

vio::InitMode parseInitMode(const std::string& s) {
  if (s == "lis") return vio::InitMode::kLis;
  if (s == "visual") return vio::InitMode::kVisual;
  return vio::InitMode::kAuto;
}

}  // namespace

vio::VioConfig loadVioConfig(const std::string& yaml_path) {
  const YAML::Node root = loadConfigRoot(yaml_path);
  vio::VioConfig c;
  if (root.IsNull()) return c;
  std::string depth_mode = vio::toString(c.depth_mode), init = vio::toString(c.init);
  YamlSection s(yaml_path, "vio");
  s.bind("window", c.window)
      .bind("min_parallax_px", c.min_parallax_px)
      .bind("min_tracked_for_parallax", c.min_tracked_for_parallax)
      .bind("focal_px", c.focal_px)
      .bind("max_keyframe_interval_s", c.max_keyframe_interval_s)
      .bind("sigma_px", c.sigma_px)
      .bind("robust_px", c.robust_px)
      .bind("outlier_px", c.outlier_px)
      .bind("min_observations", c.min_observations)
      .bind("max_features", c.max_features)
      .bindChoice("depth_mode", depth_mode, {"fixed", "factor", "off"})
      .bind("depth_sigma_m", c.depth_sigma_m)
      .bind("depth_sigma_rel", c.depth_sigma_rel)
      .bind("depth_sigma_spread", c.depth_sigma_spread)
      .bind("max_iterations", c.max_iterations)
      .bind("max_solver_ms", c.max_solver_ms)
      .bind("estimate_extrinsic", c.estimate_extrinsic)
      .bind("estimate_time_offset", c.estimate_time_offset)
      .bind("relative_covariance", c.relative_covariance)
      .bindSeconds("max_time_offset_s", c.max_time_offset_s, positive("s"))
      .bindSeconds("time_offset_sigma_s", c.time_offset_sigma_s, positive("s"))
      .bind("imu_midpoint", c.imu_midpoint)
      .bindChoice("init", init, {"auto", "lis", "visual"})
      .bind("init_min_parallax_px", c.init_min_parallax_px)
      .bind("init_sigma_position_m", c.init_sigma_position_m)
      .bind("lis_sigma_rotation_rad", c.lis_sigma_rotation_rad)
      .bind("lis_sigma_velocity", c.lis_sigma_velocity)
      .bind("seed_max_median_px", c.seed_max_median_px)
      .bind("seed_min_observations", c.seed_min_observations)
      .bind("lis_sigma_gyro_bias", c.lis_sigma_gyro_bias)
      .bind("lis_sigma_acc_bias", c.lis_sigma_acc_bias)
      .bind("lis_bias_prior_sigma_gyro", c.lis_bias_prior_sigma_gyro)
      .bind("lis_bias_prior_sigma_acc", c.lis_bias_prior_sigma_acc)
      .bind("acc_bias_prior_sigma", c.acc_bias_prior_sigma)
      .bind("align_sigma_rotation_rad", c.align_sigma_rotation_rad)
      .bind("align_sigma_velocity", c.align_sigma_velocity)
      .bind("align_sigma_gyro_bias", c.align_sigma_gyro_bias)
      .bind("align_sigma_acc_bias", c.align_sigma_acc_bias)
      .bind("init_min_acc_excitation", c.init_min_acc_excitation)
      .bind("init_max_scale_rel_sigma", c.init_max_scale_rel_sigma)
      .bind("scale_check_span_s", c.scale_check_span_s)
      .bind("scale_check_every_s", c.scale_check_every_s)
      .bind("scale_check_max_rel_sigma", c.scale_check_max_rel_sigma)
      .bind("scale_check_min_change", c.scale_check_min_change)
      .bind("scale_check_max_change", c.scale_check_max_change)
      .bind("scale_check_bias_sigma", c.scale_check_bias_sigma)
      .bind("ground_height_m", c.ground_height_m)
      .bind("ground_sigma_m", c.ground_sigma_m)
      .bind("ground_slope_sigma_rad", c.ground_slope_sigma_rad)
      .bind("ground_gate_rel", c.ground_gate_rel)
      .bind("ground_max_range_m", c.ground_max_range_m)
      .bind("ground_check_every_s", c.ground_check_every_s)
      .bind("ground_check_min_points", c.ground_check_min_points)
      .bind("ground_check_cluster_rel", c.ground_check_cluster_rel)
      .bind("min_tracked", c.min_tracked)
      .bind("coast_max_s", c.coast_max_s)
      .bind("max_acc_bias", c.max_acc_bias)
      .bind("max_gyro_bias", c.max_gyro_bias)
      .bind("max_jump_m", c.max_jump_m)
      .bind("max_height_jump_m", c.max_height_jump_m)
      .bind("max_turn_deg", c.max_turn_deg)
      .bind("max_speed", c.max_speed)
      .bindSeconds("max_imu_gap_s", c.max_imu_gap_s, positive("s"));
  const YAML::Node node = root["vio"];
  s.apply(node);
  c.depth_mode = parseDepthMode(depth_mode);
  c.init = parseInitMode(init);
  checkSectionValid(yaml_path, node, "vio", c.validate());
  return c;
}

}  // namespace drover::io
