#pragma once
// The `odometry:` section of a platform config (config/*.yaml) -> pipeline::OdometryConfig. Every key is optional
// (left out = the default in the component's Config, whose header gives its unit); an unknown key or a bad value is
// an IoError naming the file, the line and the dotted key. Sections and keys:
//   odometry: use_imu, deskew, min_points, imu_wait [s], lidar_sigma_position [m], lidar_sigma_rotation [rad],
//             lidar_sigma_rotation_unaided [rad] (a degenerate sweep without the VIS's factor; 0 = the same),
//             degenerate_sigma, use_imu_orientation (take a 9-axis unit's orientation at initialisation; false
//             when it is not of the IMU's acc/gyro frame, as LIO-SAM's extrinsicRPY != extrinsicRot says)
//             degenerate_pose_from_match (a degenerate match keeps its own pose, as LIO-SAM; default: the smoother's)
//             moving_start_restart [sweeps], moving_start_speed [m/s] (a start in motion: pipeline/odometry_config.hpp),
//             static_start_sigma_velocity [m/s] (the first velocity's sigma after a static start; 0 = off)
//     layout:       n_rings, vertical_fov_min_deg, vertical_fov_max_deg, columns, scan_period [s],
//                   spin (ccw | cw), ring_source (elevation | order), order_top_down, min_range, max_range [m]
//     features:     edge_threshold, surf_threshold (LIO-SAM edgeThreshold/surfThreshold), surf_leaf, edge_leaf,
//                   full_leaf [m], sub_regions, max_edges_per_region, ... (lidar/feature_extractor.hpp)
//     local_map:    surrounding_radius [m], keyframe_density [m], recent_window [s], edge_leaf, plane_leaf [m],
//                   retire_radius [m], retire_age [s], ... (lidar/local_map.hpp)
//     matcher:      max_iterations, degeneracy_threshold, degeneracy_threshold_per_correspondence, kernel
//                   (lio-sam | huber), ...
//     keyframes:    distance [m], angle [rad]
//     imu:          gyro_noise_density, acc_noise_density, gyro_bias_random_walk, acc_bias_random_walk, gravity
//     smoother:     window, max_iterations, ...
//     vis_fusion:   factor, factor_degenerate_only, initial_guess, initial_guess_degenerate_only (the VIS's motion in
//                   the LIS, while a VIS runs), sigma_position [m],
//                   sigma_position_ratio [m/m], sigma_rotation [rad], sigma_rotation_ratio [rad/rad],
//                   window_covariance (bool), window_floor_position [m], window_floor_rotation [rad], min_features,
//                   full_features, warmup [s], max_age [s], max_keyframe_gap [s], standing_speed [m/s],
//                   keyframe_gap_min_distance [m], keyframe_gap_velocity_tolerance [m/s],
//                   max_velocity_difference [m/s],
//                   max_velocity_difference_ratio [m/s per m/s], max_velocity_difference_growth [m/s^2],
//                   max_position_difference [m], max_acceleration_difference [m/s^2], reset_after [s]
//                   (pipeline/visual_motion.hpp)
//     static_hold:  sigma [m and rad per sweep; 0 = off], max_velocity [m/s], max_rotation [rad] (a static start
//                   held at rest until the IMU says it moved: pipeline/static_hold.hpp)
//   loop: (its own top-level section) see io/odometry/loop_config_io.hpp
// Lives in its own library (drover_io_odometry) so that the readers do not depend on the odometry modules.
#include <string>

#include "pipeline/odometry_config.hpp"

namespace drover::io {

// Throws IoError (file, line, key) for a missing file, invalid YAML, unknown key or bad value, and when the result
// fails OdometryConfig::validate() (naming the file).
pipeline::OdometryConfig loadOdometryConfig(const std::string& yaml_path);

}  // namespace drover::io
