#pragma once
// The `vio:` section of a platform config -> vio::VioConfig (the VIS's sliding window). Every key is optional (left
// out = the default in src/vio/vio_config.hpp, whose comments give the units); an unknown key or a bad value is an
// IoError naming the file, the line and the dotted key. Keys:
//   vio: window, min_parallax_px [px], min_tracked_for_parallax, focal_px [px],
//        max_keyframe_interval_s [s], sigma_px [px], robust_px [px],
//        outlier_px [px], min_observations, max_features, depth_mode (fixed | factor | off), depth_sigma_m [m],
//        depth_sigma_rel, depth_sigma_spread, max_iterations, max_solver_ms [ms], estimate_extrinsic (bool),
//        estimate_time_offset (bool), relative_covariance (bool), time_offset_sigma_s [s], max_time_offset_s [s], imu_midpoint (bool),
//        init (auto | lis | visual), init_min_parallax_px [px],
//        init_sigma_position_m [m], lis_sigma_rotation_rad / align_sigma_rotation_rad [rad],
//        lis_sigma_velocity / align_sigma_velocity [m/s], lis_sigma_gyro_bias / align_sigma_gyro_bias [rad/s],
//        lis_sigma_acc_bias / align_sigma_acc_bias [m/s^2], seed_max_median_px [px], seed_min_observations,
//        init_min_acc_excitation [m/s^2], init_max_scale_rel_sigma,
//        scale_check_span_s [s], scale_check_every_s [s], scale_check_max_rel_sigma, scale_check_min_change,
//        scale_check_max_change, scale_check_bias_sigma [m/s^2], ground_height_m [m], ground_sigma_m [m],
//        ground_slope_sigma_rad [rad], ground_gate_rel, ground_max_range_m [m], ground_check_every_s [s],
//        ground_check_min_points, ground_check_cluster_rel, min_tracked, coast_max_s [s], max_acc_bias [m/s^2],
//        max_gyro_bias [rad/s], max_jump_m [m], max_height_jump_m [m], max_turn_deg [deg], max_speed [m/s],
//        max_imu_gap_s [s]
#include <string>

#include "vio/vio_config.hpp"

namespace drover::io {

// Throws IoError (file, line, key) for a missing file, invalid YAML, unknown key, bad value or a config that fails
// VioConfig::validate().
vio::VioConfig loadVioConfig(const std::string& yaml_path);

}  // namespace drover::io
