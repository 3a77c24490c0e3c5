#include "lidar/keyframe_policy.hpp"

#include <cmath>
#include <stdexcept>

#include "geometry/se3.hpp"
#include "geometry/so3.hpp"

namespace drover::lidar {

std::string KeyframePolicyConfig::validate() const {
  if (!std::isfinite(distance) || distance <= 0.0) {
    return "keyframe distance must be finite and > 0 m, got " + std::to_string(distance);
  }
  if (!std::isfinite(angle) || angle <= 0.0) {
    return "keyframe angle must be finite and > 0 rad, got " + std::to_string(angle);
  }
  return {};
}

KeyframePolicy::KeyframePolicy(const KeyframePolicyConfig& config) : config_(config) {
  if (const std::string error = config_.validate(); !error.empty()) {
    throw std::invalid_argument("KeyframePolicy: " + error);
  }
}

KeyframeDecision KeyframePolicy::decide(const Eigen::Isometry3d& T_world_lastkf,
                                        const Eigen::Isometry3d& T_world_current) const {
  if (!T_world_lastkf.matrix().allFinite() || !T_world_current.matrix().allFinite()) {
    throw std::invalid_argument("KeyframePolicy::decide: non-finite pose");
  }
  const Eigen::Isometry3d T_lastkf_current = geometry::inverse(T_world_lastkf) * T_world_current;
  KeyframeDecision decision;
  decision.distance = T_lastkf_current.translation().norm();
  decision.angle = geometry::rotationAngle(T_lastkf_current.linear());
  decision.is_keyframe = decision.distance >= config_.distance || decision.angle >= config_.angle;
  return decision;
}

}  // namespace drover::lidar
