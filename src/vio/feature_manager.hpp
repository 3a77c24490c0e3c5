#pragma once
// The features of the sliding window (VINS-Mono's FeatureManager, Qin et al. T-RO 2018, Sec. VI): each tracked
// feature is anchored in the first window frame that saw it, with its depth along that camera's z axis (the
// estimator solves its inverse). A KLT track, once lost, never returns; outlier removal may leave gaps.
// Window frames are indexed 0 (oldest) .. n-1 (newest); sliding the window re-indexes them.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <vector>

namespace drover::vio {

// One feature in one frame, as the front end and the depth association give it.
struct FrameFeature {
  std::uint64_t id = 0;
  Eigen::Vector2d normalized = Eigen::Vector2d::Zero();  // undistorted (x / z, y / z)
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();    // [normalised units / s]
  double lidar_depth = 0;   // [m] along the camera z axis, 0 = none
  double depth_spread = 0;  // [m] range spread of the lidar neighbours behind lidar_depth
};

struct Observation {
  int frame = 0;            // window index
  Eigen::Vector2d normalized = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();
  double td = 0;            // [s] the time offset the frame's stamp was computed with
  double lidar_depth = 0;   // [m], 0 = none
  double depth_spread = 0;  // [m]
};

struct Feature {
  std::uint64_t id = 0;
  std::vector<Observation> obs;   // in frame order; the first is the anchor
  double depth = 0;               // [m] in the anchor camera; <= 0: not triangulated yet
  bool lidar_anchor = false;      // depth taken from the lidar at the anchor frame
  double inverse_depth = 0;       // [1/m] the solver's parameter block
  int start() const { return obs.front().frame; }
  int end() const { return obs.back().frame; }
};

class FeatureManager {
 public:
  // Adds the newest frame (window index `frame`) and returns the average parallax [normalised units] between
  // frames frame-2 and frame-1 over the features seen in both (VINS-Mono's compensatedParallax2 without the
  // rotation compensation it leaves out too), or -1 when no feature spans them. `td` is the frame's time offset.
  double addFrame(int frame, const std::vector<FrameFeature>& features, double td);
  int lastTracked() const { return last_tracked_; }  // features of the newest frame already in the window

  // Features usable in the solve: >= min_obs observations and anchored before the second-newest frame.
  bool usable(const Feature& f, int newest, int min_obs) const;
  // Depth for features that have none: the anchor's lidar depth when there is one (use_lidar), else the linear
  // (DLT) triangulation from all observations; T_world_cam per window frame.
  void initializeDepths(const std::vector<Eigen::Isometry3d>& T_world_cam, bool use_lidar);
  // Drops features whose solved depth is not positive (VINS removeFailures).
  void removeFailures();
  // Drops the observation of one feature at a window frame (an outlier); a feature left with none disappears.
  void removeObservation(std::uint64_t id, int frame);
  // The oldest frame leaves: features anchored there move to frame 1 with their depth re-expressed (VINS
  // removeBackShiftDepth) or, with a lidar depth at the new anchor, take that; features seen only there vanish.
  void removeOldest(const Eigen::Isometry3d& T_world_cam0, const Eigen::Isometry3d& T_world_cam1, bool use_lidar);
  // The second-newest frame (index newest-1) leaves; the newest takes its index (VINS removeFront).
  void removeSecondNewest(int newest);
  void clear();

  std::map<std::uint64_t, Feature>& features() { return features_; }
  const std::map<std::uint64_t, Feature>& features() const { return features_; }

 private:
  std::map<std::uint64_t, Feature> features_;
  int last_tracked_ = 0;
};

// The point of a feature's anchor observation at depth d [m] in the anchor camera.
inline Eigen::Vector3d anchorPoint(const Feature& f, double depth) {
  return depth * Eigen::Vector3d(f.obs.front().normalized.x(), f.obs.front().normalized.y(), 1.0);
}

}  // namespace drover::vio
