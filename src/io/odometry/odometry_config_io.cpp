#include "io/odometry/odometry_config_io.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "io/config.hpp"
#include "io/error.hpp"
#include "io/odometry/loop_config_io.hpp"
#include "io/text_parsing.hpp"
#include "io/user_values.hpp"
#include "io/yaml_section.hpp"

namespace drover::io {
namespace {

// Enumerations travel as strings through the binder and are checked here.
struct EnumStrings {
  std::string spin = "ccw", ring_source, kernel = "lio-sam";
};

void bindLayout(YamlSection& s, lidar::ScanLayoutConfig& c, EnumStrings& e) {
  s.bind("n_rings", c.n_rings)
      .bind("vertical_fov_min_deg", c.vertical_fov_min_deg)
      .bind("vertical_fov_max_deg", c.vertical_fov_max_deg)
      .bind("columns", c.columns)
      .bindSeconds("scan_period", c.scan_period, positive("s"))
      .bindChoice("spin", e.spin, {"ccw", "cw"})
      .bindChoice("ring_source", e.ring_source, {"elevation", "order"})
      .bind("order_top_down", c.order_top_down)
      .bind("seam_tolerance_deg", c.seam_tolerance_deg)
      .bind("min_range", c.min_range)
      .bind("max_range", c.max_range);
}

// Float fields of the feature extractor go through doubles.
struct FeatureFloats {
  double edge_threshold, surf_threshold, occlusion_depth_gap, parallel_ratio, edge_leaf, surf_leaf, full_leaf;
};

void bindFeatures(YamlSection& s, lidar::FeatureExtractorConfig& c, FeatureFloats& f) {
  s.bind("columns", c.columns)
      .bind("min_range", c.min_range)
      .bind("max_range", c.max_range)
      .bind("half_window", c.half_window)
      .bind("edge_threshold", f.edge_threshold)
      .bind("surf_threshold", f.surf_threshold)
      .bind("sub_regions", c.sub_regions)
      .bind("max_edges_per_region", c.max_edges_per_region)
      .bind("suppression_radius", c.suppression_radius)
      .bind("max_column_gap", c.max_column_gap)
      .bind("occlusion_depth_gap", f.occlusion_depth_gap)
      .bind("parallel_ratio", f.parallel_ratio)
      .bind("edge_leaf", f.edge_leaf)
      .bind("surf_leaf", f.surf_leaf)
      .bind("full_leaf", f.full_leaf);
}

void bindLocalMap(YamlSection& s, lidar::LocalMapConfig& c) {
  s.bind("surrounding_radius", c.surrounding_radius)
      .bind("keyframe_density", c.keyframe_density)
      .bind("recent_window", c.recent_window)
      .bind("recent_count", c.recent_count)
      .bind("edge_leaf", c.edge_leaf)
      .bind("plane_leaf", c.plane_leaf)
      .bind("full_leaf", c.full_leaf)
      .bind("cache_capacity", c.cache_capacity)
      .bind("retire_radius", c.retire_radius)
      .bind("retire_age", c.retire_age);
}

void bindMatcher(YamlSection& s, lidar::ScanMatcherConfig& c, EnumStrings& e) {
  s.bind("max_iterations", c.max_iterations)
      .bind("convergence_translation", c.convergence_translation)
      .bind("convergence_rotation", c.convergence_rotation)
      .bind("neighbors", c.neighbors)
      .bind("max_neighbor_distance", c.max_neighbor_distance)
      .bind("edge_eigen_ratio", c.edge_eigen_ratio)
      .bind("plane_tolerance", c.plane_tolerance)
      .bind("plane_min_aspect", c.plane_min_aspect)
      .bindChoice("kernel", e.kernel, {"lio-sam", "huber"})
      .bind("min_weight", c.min_weight)
      .bind("huber_delta", c.huber_delta)
      .bind("degeneracy_threshold", c.degeneracy_threshold)
      .bind("degeneracy_threshold_per_correspondence", c.degeneracy_threshold_per_correspondence)
      .bind("min_edge_features", c.min_edge_features)
      .bind("min_plane_features", c.min_plane_features)
      .bind("min_correspondences", c.min_correspondences);
}

void bindImu(YamlSection& s, imu::PreintegrationConfig& c) {
  s.bind("gyro_noise_density", c.gyro_noise_density)
      .bind("acc_noise_density", c.acc_noise_density)
      .bind("gyro_bias_random_walk", c.gyro_bias_random_walk)
      .bind("acc_bias_random_walk", c.acc_bias_random_walk)
      .bind("integration_sigma", c.integration_sigma)
      .bind("gravity", c.gravity);
}

void bindSmoother(YamlSection& s, backend::FixedLagSmootherConfig& c) {
  s.bind("window", c.window)
      .bind("prior_sigma_position", c.prior_sigma_position)
      .bind("prior_sigma_rotation", c.prior_sigma_rotation)
      .bind("prior_sigma_velocity", c.prior_sigma_velocity)
      .bind("prior_sigma_gyro_bias", c.prior_sigma_gyro_bias)
      .bind("prior_sigma_acc_bias", c.prior_sigma_acc_bias)
      .bind("max_iterations", c.max_iterations)
      .bind("max_velocity", c.max_velocity)
      .bind("max_bias", c.max_bias);
}

void bindVisFusion(YamlSection& s, pipeline::VisualMotionConfig& c) {
  s.bind("factor", c.factor)
      .bind("factor_degenerate_only", c.factor_degenerate_only)
      .bind("initial_guess", c.initial_guess)
      .bind("initial_guess_degenerate_only", c.initial_guess_degenerate_only)
      .bind("sigma_position", c.sigma_position)
      .bind("sigma_position_ratio", c.sigma_position_ratio)
      .bind("sigma_rotation", c.sigma_rotation)
      .bind("sigma_rotation_ratio", c.sigma_rotation_ratio)
      .bind("window_covariance", c.window_covariance)
      .bind("window_floor_position", c.window_floor_position)
      .bind("window_floor_rotation", c.window_floor_rotation)
      .bind("min_features", c.min_features)
      .bind("full_features", c.full_features)
      .bindSeconds("warmup", c.warmup, atLeast(0, "s"))
      .bindSeconds("max_age", c.max_age, atLeast(0, "s"))
      .bindSeconds("max_keyframe_gap", c.max_keyframe_gap, atLeast(0, "s"))
      .bind("standing_speed", c.standing_speed)
      .bind("keyframe_gap_min_distance", c.keyframe_gap_min_distance)
      .bind("keyframe_gap_velocity_tolerance", c.keyframe_gap_velocity_tolerance)
      .bind("max_velocity_difference", c.max_velocity_difference)
      .bind("max_velocity_difference_ratio", c.max_velocity_difference_ratio)
      .bind("max_velocity_difference_growth", c.max_velocity_difference_growth)
      .bind("max_position_difference", c.max_position_difference)
      .bind("max_acceleration_difference", c.max_acceleration_difference)
      .bindSeconds("reset_after", c.reset_after, atLeast(0, "s"));
}

// The binder has already checked the values (bindChoice), with their lines.
void applyEnums(const EnumStrings& e, pipeline::OdometryConfig& c) {
  c.layout.spin = e.spin == "cw" ? lidar::SpinDirection::kClockwise : lidar::SpinDirection::kCounterClockwise;
  if (e.ring_source == "elevation") c.layout.ring_source = lidar::RingSource::kElevation;
  if (e.ring_source == "order") c.layout.ring_source = lidar::RingSource::kOrder;
  c.matcher.kernel = e.kernel == "huber" ? lidar::RobustKernel::kHuber : lidar::RobustKernel::kLioSam;
}

}  // namespace

pipeline::OdometryConfig loadOdometryConfig(const std::string& yaml_path) {
  const YAML::Node root = loadConfigRoot(yaml_path);
  pipeline::OdometryConfig c;
  if (root.IsNull()) return c;
  EnumStrings e;
  const lidar::FeatureExtractorConfig& fc = c.features;
  FeatureFloats f{fc.edge_threshold, fc.surf_threshold, fc.occlusion_depth_gap, fc.parallel_ratio,
                  fc.edge_leaf,      fc.surf_leaf,      fc.full_leaf};
  YamlSection top(yaml_path, "odometry");
  top.bind("use_imu", c.use_imu)
      .bind("deskew", c.deskew)
      .bind("min_points", c.min_points)
      .bindSeconds("imu_wait", c.imu_wait, atLeast(0, "s"))
      .bind("lidar_sigma_position", c.lidar_sigma_position)
      .bind("lidar_sigma_rotation", c.lidar_sigma_rotation)
      .bind("lidar_sigma_rotation_unaided", c.lidar_sigma_rotation_unaided)
      .bind("degenerate_sigma", c.degenerate_sigma)
      .bind("gravity_roll_pitch", c.gravity_roll_pitch)
      .bind("degenerate_pose_from_match", c.degenerate_pose_from_match)
      .bind("deskew_refinements", c.deskew_refinements)
      .bind("degenerate_restart_sweeps", c.degenerate_restart_sweeps)
      .bind("moving_start_restart", c.moving_start_restart)
      .bind("moving_start_speed", c.moving_start_speed)
      .bind("static_start_sigma_velocity", c.static_start_sigma_velocity)
      .bind("use_imu_orientation", c.initializer.use_orientation)
      .nested("layout", [&](YamlSection& s) { bindLayout(s, c.layout, e); })
      .nested("features", [&](YamlSection& s) { bindFeatures(s, c.features, f); })
      .nested("local_map", [&](YamlSection& s) { bindLocalMap(s, c.local_map); })
      .nested("matcher", [&](YamlSection& s) { bindMatcher(s, c.matcher, e); })
      .nested("keyframes", [&](YamlSection& s) {
        s.bind("distance", c.keyframes.distance).bind("angle", c.keyframes.angle);
      })
      .nested("imu", [&](YamlSection& s) { bindImu(s, c.preintegration); })
      .nested("smoother", [&](YamlSection& s) { bindSmoother(s, c.smoother); })
      .nested("vis_fusion", [&](YamlSection& s) { bindVisFusion(s, c.vis_fusion); })
      .nested("static_hold", [&](YamlSection& s) {
        s.bind("sigma", c.static_hold.sigma)
            .bind("max_velocity", c.static_hold.max_velocity)
            .bind("max_rotation", c.static_hold.max_rotation);
      });
  top.apply(root["odometry"]);
  applyEnums(e, c);
  // The loop closure has its own top-level section; the matcher and submap of its verifier follow the odometry's.
  c.loop.verifier.matcher = c.matcher;
  c.loop.verifier.submap.edge_leaf = c.local_map.edge_leaf;
  c.loop.verifier.submap.plane_leaf = c.local_map.plane_leaf;
  LoopEnumStrings le;
  YamlSection loop(yaml_path, "loop");
  bindLoopSection(loop, c.loop, le);
  loop.apply(root["loop"]);
  applyLoopEnums(le, c.loop);
  c.features.edge_threshold = static_cast<float>(f.edge_threshold);
  c.features.surf_threshold = static_cast<float>(f.surf_threshold);
  c.features.occlusion_depth_gap = static_cast<float>(f.occlusion_depth_gap);
  c.features.parallel_ratio = static_cast<float>(f.parallel_ratio);
  c.features.edge_leaf = static_cast<float>(f.edge_leaf);
  c.features.surf_leaf = static_cast<float>(f.surf_leaf);
  c.features.full_leaf = static_cast<float>(f.full_leaf);
  // The IMU noise model is one: the propagator and the initializer use the same gravity.
  c.propagator.gravity = c.initializer.gravity = c.preintegration.gravity;
  if (std::string err = c.validate(); !err.empty()) fail(yaml_path, "section 'odometry'", err);
  return c;
}

}  // namespace drover::io
