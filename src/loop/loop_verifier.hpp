#pragma once
// Geometric verification of a loop candidate (LIO-SAM's performLoopClosure: ICP of the current keyframe against
// the candidate's submap, accepted by fitness). Drover reuses the odometry's scan matcher (point-to-line and
// point-to-plane Gauss-Newton on SE(3), lidar/scan_matcher.hpp) instead of PCL's ICP: the query keyframe's LOAM
// features are registered to a local map built from the candidate keyframe and its neighbours, all expressed in
// the candidate's lidar frame, starting from a guess (the Scan Context yaw and lateral offset, or the current
// trajectory estimate for radius-search candidates).
//
// Accepted when the match converged, is not degenerate, its RMS point-to-feature distance is below max_fitness,
// enough of the query's features found correspondences, and the solution stayed near the guess (a match that
// slid far from a Scan Context guess has found another structure). The loop factor's covariance is the matcher's
// (inverse weighted J^T J scaled by the residual) plus a floor: thousands of correspondences make the fit's own
// covariance millimetre-small, which would let one loop overrule every odometry edge.
#include <Eigen/Geometry>
#include <span>
#include <string>

#include "geometry/se3.hpp"
#include "lidar/feature_set.hpp"
#include "lidar/local_map.hpp"
#include "lidar/scan_matcher.hpp"

namespace drover::loop {

struct LoopVerifierConfig {
  lidar::ScanMatcherConfig matcher;         // the odometry's matcher settings (max_iterations, kernels, ...)
  lidar::LocalMapConfig submap;             // leaves of the candidate submap (radius and density are not used: every
                                            // submap keyframe given is kept)
  double max_fitness = 0.25;                // [m] RMS point-to-feature distance at the solution
  int min_inliers = 100;                    // [-] accepted edge + plane correspondences at the solution
  double min_inlier_ratio = 0.35;           // [-] of the query's edges + planes
  double max_correction_translation = 4.0;  // [m] |translation| of guess^-1 * solution
  double max_correction_rotation = 0.35;    // [rad] angle of guess^-1 * solution (20 deg)
  double sigma_floor_position = 0.05;       // [m] added in quadrature to the fit's position sigma
  double sigma_floor_rotation = 0.005;      // [rad] added in quadrature to the fit's rotation sigma
  // A fit worse than this scales the whole covariance by (fitness / sigma_fitness_reference)^2: on the farm the
  // loops' error grows with their fitness (NEES < 0.1 below 0.05 m, 20-28 at 0.15-0.18 m against the floors' claim).
  // 0 leaves the covariance as the fit and the floors give it (the default); the drover preset sets 0.05 m.
  double sigma_fitness_reference = 0.0;     // [m]
  std::string validate() const;             // empty when valid
};

// One keyframe of the candidate's submap: its features (lidar frame) and pose in any common frame.
struct SubmapKeyframe {
  const lidar::FeatureSet* features = nullptr;
  Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();
};

struct LoopVerification {
  bool accepted = false;
  std::string reason;  // one line: why accepted or rejected, with the numbers
  // Relative pose of the query lidar in the candidate lidar frame (the loop factor's measurement).
  Eigen::Isometry3d T_candidate_query = Eigen::Isometry3d::Identity();
  std::string match_status;  // lidar::toString(MatchStatus)
  bool converged = false, degenerate = false;
  int iterations = 0;
  double fitness = 0;                 // [m] RMS point-to-feature distance
  int inliers = 0;                    // edge + plane correspondences
  double inlier_ratio = 0;            // inliers / (query edges + planes)
  double correction_translation = 0;  // [m] |guess^-1 * solution| translation
  double correction_rotation = 0;     // [rad]
  // Covariance of the decoupled error [dp (candidate frame, m); dphi (right, rad)] of T_candidate_query, as
  // backend::RelativePoseFactor and PoseGraph edges take it; information() is its inverse. The inverse is not
  // stored: every verification is kept as a loop event (thousands over an hour), and 288 bytes each add up.
  geometry::Matrix6d covariance = geometry::Matrix6d::Identity();
  geometry::Matrix6d information() const;
};

class LoopVerifier {
 public:
  // Throws std::invalid_argument when config.validate() fails.
  explicit LoopVerifier(const LoopVerifierConfig& config = {});

  // Registers `query` (features in the query lidar frame) to the submap around the candidate, starting at
  // T_candidate_query_guess. The submap's poses may be in any world frame; candidate is the index in `submap` of
  // the candidate keyframe, whose frame the result refers to. Throws std::invalid_argument for an empty submap, a
  // bad candidate index, a null features pointer or a non-finite pose.
  LoopVerification verify(const lidar::FeatureSet& query, std::span<const SubmapKeyframe> submap, std::size_t candidate,
                          const Eigen::Isometry3d& T_candidate_query_guess) const;

  const LoopVerifierConfig& config() const { return config_; }

 private:
  LoopVerifierConfig config_;
  lidar::ScanMatcher matcher_;
};

}  // namespace drover::loop
