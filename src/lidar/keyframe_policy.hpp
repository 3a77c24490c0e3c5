#pragma once
// When a scan becomes a keyframe (LIO-SAM's saveFrame(): surroundingkeyframeAddingDistThreshold and
// surroundingkeyframeAddingAngleThreshold). LIO-SAM compares each Euler angle of the relative rotation with the
// threshold; we compare the geodesic rotation angle |Log(R_lastkf_current)|, which does not depend on an Euler
// convention and is never smaller than any single Euler angle's magnitude for small motions.
#include <Eigen/Geometry>
#include <string>

namespace drover::lidar {

struct KeyframePolicyConfig {
  double distance = 1.0;  // [m] translation since the last keyframe that makes a keyframe
  double angle = 0.2;     // [rad] rotation angle since the last keyframe that makes a keyframe
  // Empty when valid: both finite and > 0.
  std::string validate() const;
};

// The decision with the motion that led to it, so that callers can log why.
struct KeyframeDecision {
  bool is_keyframe = false;
  double distance = 0.0;  // [m] |t_lastkf_current|
  double angle = 0.0;     // [rad] rotation angle of R_lastkf_current, in [0, pi]
};

class KeyframePolicy {
 public:
  // Throws std::invalid_argument when config.validate() fails.
  explicit KeyframePolicy(const KeyframePolicyConfig& config = {});

  // A keyframe when the motion from the last keyframe reaches either threshold (>=). Poses are T_world_lidar.
  // Throws std::invalid_argument on a non-finite pose.
  KeyframeDecision decide(const Eigen::Isometry3d& T_world_lastkf, const Eigen::Isometry3d& T_world_current) const;
  bool isKeyframe(const Eigen::Isometry3d& T_world_lastkf, const Eigen::Isometry3d& T_world_current) const {
    return decide(T_world_lastkf, T_world_current).is_keyframe;
  }

  const KeyframePolicyConfig& config() const { return config_; }

 private:
  KeyframePolicyConfig config_;
};

}  // namespace drover::lidar
