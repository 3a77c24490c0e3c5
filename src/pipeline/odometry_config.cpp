#include "pipeline/odometry_config.hpp"

#include <cmath>

namespace drover::pipeline {
namespace {

std::string prefixed(const char* component, const std::string& error) {
  return error.empty() ? error : std::string(component) + ": " + error;
}

}  // namespace

OdometryConfig OdometryConfig::kittiHdl64() {
  OdometryConfig c;
  c.layout = lidar::ScanLayoutConfig::kittiHdl64();
  c.features.columns = c.layout.columns;
  c.features.min_range = static_cast<float>(c.layout.min_range);
  c.features.max_range = static_cast<float>(c.layout.max_range);
  return c;
}

LoopClosureConfig OdometryConfig::loopClosure() const {
  LoopClosureConfig c = loop;
  c.graph.yaw_only_rotation = use_imu && loop.four_dof_with_imu;
  return c;
}

std::string OdometryConfig::validate() const {
  if (deskew_refinements < 0 || deskew_refinements > 10)
    return "deskew_refinements must be in [0, 10], got " + std::to_string(deskew_refinements);
  if (!std::isfinite(static_start_sigma_velocity) || static_start_sigma_velocity < 0)
    return "static_start_sigma_velocity must be finite and >= 0, got " + std::to_string(static_start_sigma_velocity);
  if (!(moving_start_speed >= 0))
    return "moving_start_speed must be finite and >= 0, got " + std::to_string(moving_start_speed);
  if (moving_start_restart < 0)
    return "moving_start_restart must be >= 0, got " + std::to_string(moving_start_restart);
  if (degenerate_restart_sweeps < 0)
    return "degenerate_restart_sweeps must be >= 0, got " + std::to_string(degenerate_restart_sweeps);
  if (min_points < 1) return "min_points must be >= 1, got " + std::to_string(min_points);
  for (const auto& [name, v] : {std::pair<const char*, double>{"imu_wait", imu_wait},
                                {"lidar_sigma_position", lidar_sigma_position},
                                {"lidar_sigma_rotation", lidar_sigma_rotation},
                                {"degenerate_sigma", degenerate_sigma}})
    if (!std::isfinite(v) || v <= 0) return std::string(name) + " must be finite and > 0, got " + std::to_string(v);
  if (!std::isfinite(lidar_sigma_rotation_unaided) || lidar_sigma_rotation_unaided < 0)
    return "lidar_sigma_rotation_unaided must be finite and >= 0, got " + std::to_string(lidar_sigma_rotation_unaided);
  const std::pair<const char*, std::string> parts[] = {
      {"layout", layout.validate()},          {"features", features.validate()},
      {"local_map", local_map.validate()},    {"matcher", matcher.validate()},
      {"keyframes", keyframes.validate()},    {"preintegration", preintegration.validate()},
      {"propagator", propagator.validate()},  {"initializer", initializer.validate()},
      {"smoother", smoother.validate()},      {"loop", loop.validate()},
      {"vis_fusion", vis_fusion.validate()},  {"static_hold", static_hold.validate()}};
  for (const auto& [name, error] : parts)
    if (!error.empty()) return prefixed(name, error);
  return {};
}

}  // namespace drover::pipeline
