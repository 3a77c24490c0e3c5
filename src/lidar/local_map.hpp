#pragma once
// The keyframe map that scan matching runs against (LIO-SAM mapOptimization's extractSurroundingKeyFrames /
// extractCloud, without its global state). Every keyframe keeps its features once, in its own lidar frame,
// downsampled with the map's leaf sizes; build() assembles the edges and planes of the keyframes near a point
// (plus the most recent ones) into the world frame, downsamples them again and indexes them with two k-d trees.
// World-frame copies of keyframe clouds are cached per keyframe so consecutive builds transform only keyframes
// that entered the local map or whose pose changed (updatePose, e.g. after a loop closure).
//
// Not thread-safe for mutation: addKeyframe/updatePose/build must not run concurrently with anything else. The
// const queries (nearestEdges/nearestPlanes and the accessors) may run from many threads at once. A moved-from
// LocalMap may only be assigned to or destroyed.
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "lidar/feature_set.hpp"
#include "types/time.hpp"

namespace drover::lidar {

struct LocalMapConfig {
  double surrounding_radius = 50.0;  // [m] keyframes whose position is this close to the centre (LIO-SAM's
                                     // surroundingKeyframeSearchRadius)
  double keyframe_density = 2.0;     // [m] among the surrounding keyframes keep the newest one per cube of this
                                     // side (surroundingKeyframeDensity); 0 keeps all
  double recent_window = 10.0;       // [s] keyframes this close in time to the newest one are always included,
                                     // however far they are (LIO-SAM's 10 s); 0 disables
  int recent_count = 0;              // [-] the newest N keyframes are always included as well; 0 disables
  double edge_leaf = 0.2;            // [m] voxel leaf of keyframe and local-map edges (mappingCornerLeafSize)
  double plane_leaf = 0.4;           // [m] voxel leaf of keyframe and local-map planes (mappingSurfLeafSize)
  double full_leaf = 0.0;            // [m] voxel leaf applied to a keyframe's full cloud when stored; 0 keeps it
  int cache_capacity = 1000;         // [keyframes] world-frame clouds cached at most (LIO-SAM clears at 1000);
                                     // the keyframes of the current local map are never evicted
  // A map bounded by the area driven, not the time (a robot that drives the same barn all day): once a keyframe
  // is retire_age old, the keyframes at least retire_age older than it within retire_radius of it are retired:
  // their clouds are freed (their poses stay, for the trajectory and the pose graph) and the newer view of the
  // place stands for them, as it already does in the local maps (the newest keyframe per density cube). LIO-SAM
  // keeps every keyframe's clouds: retire_radius 0. 2 m, the density cube's side: with 1 m (the keyframe spacing)
  // passes that lie 1-2 m apart in the estimate never retired each other, and an hour on the farm kept 815 keyframes'
  // clouds alive instead of ~640; one pass is the same either way (farm 3.5786 / 3.5784 m, kitti05-replay 0.1849 /
  // 0.1854 m; bench/RESULTS.md).
  double retire_radius = 2.0;        // [m]; 0 keeps every keyframe's clouds
  double retire_age = 30.0;          // [s] (as the loop search's min_age, LIO-SAM's 30 s): another pass
  // Empty when valid: every value finite, radius > 0, the others >= 0, edge/plane leaves > 0, capacity >= 1.
  std::string validate() const;
};

// One keyframe as stored: features in its lidar frame (downsampled), its pose and the sweep time.
struct Keyframe {
  std::size_t index = 0;                                            // position in the map, 0..size()-1
  Time t = 0;                                                       // [ns] the FeatureSet's sweep start
  Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();  // maps keyframe lidar points to the world
  // Lidar frame, downsampled with the map's leaves; immutable, so other maps (the live loop thread's) share it
  // instead of holding a copy.
  std::shared_ptr<const FeatureSet> shared;
  bool retired = false;  // its clouds were freed (LocalMap::retire): features() is empty, local maps skip it
  const FeatureSet& features() const { return *shared; }
};

// What build() did.
struct LocalMapBuild {
  std::vector<std::size_t> keyframes;  // indices assembled, ascending
  std::size_t edge_points = 0;         // in the assembled (downsampled) edge cloud
  std::size_t plane_points = 0;        // in the assembled (downsampled) plane cloud
  std::size_t transformed = 0;         // keyframes transformed into the world in this build (cache misses)
  bool reused = false;                 // true when the selection and poses were unchanged: nothing was rebuilt
};

class LocalMap {
 public:
  // Throws std::invalid_argument when config.validate() fails.
  explicit LocalMap(const LocalMapConfig& config = {});
  ~LocalMap();
  LocalMap(LocalMap&&) noexcept;
  LocalMap& operator=(LocalMap&&) noexcept;
  LocalMap(const LocalMap&) = delete;
  LocalMap& operator=(const LocalMap&) = delete;

  // Stores a keyframe (features in the lidar frame, T_world_lidar its pose) and returns its index. Keyframes
  // should arrive in time order (the recent window is measured from the last one added). Throws
  // std::invalid_argument on a non-finite pose.
  std::size_t addKeyframe(const FeatureSet& features, const Eigen::Isometry3d& T_world_lidar);
  // The same for features another LocalMap with the same leaves already downsampled (its Keyframe::shared): stored
  // as they are, shared, not copied. Throws std::invalid_argument on a null pointer or a non-finite pose.
  std::size_t addSharedKeyframe(std::shared_ptr<const FeatureSet> downsampled, const Eigen::Isometry3d& T_world_lidar);
  // Corrects a keyframe's pose (loop closure); its cached world clouds are dropped and the next build()
  // reassembles. Throws std::invalid_argument on a bad index or non-finite pose.
  void updatePose(std::size_t index, const Eigen::Isometry3d& T_world_lidar);

  // The keyframes keyframe `index` supersedes (see retire_radius): not retired, at least retire_age older than it,
  // within retire_radius of its current position; ascending. Empty when retire_radius is 0. Throws
  // std::invalid_argument on a bad index.
  std::vector<std::size_t> supersededBy(std::size_t index) const;
  // Frees a keyframe's clouds for good (its pose, time and index stay); local maps skip it from then on. Retiring
  // twice is harmless. Throws std::invalid_argument on a bad index.
  void retire(std::size_t index);
  std::size_t retiredCount() const;
  // [bytes] the world-frame clouds cached for local maps (bounded by cache_capacity)
  std::size_t cacheBytes() const;

  // Assembles the local map around `center_world` [m] (usually the last keyframe's or the guess's position) from
  // the keyframes with index >= first_keyframe (the odometry starts a new submap there after a long degenerate
  // stretch, whose drift makes older keyframes inconsistent with the current pose). With no keyframes the
  // assembled clouds are empty.
  LocalMapBuild build(const Eigen::Vector3d& center_world, std::size_t first_keyframe = 0);

  // The assembled local map (world frame), valid until the next build()/move.
  const PointCloud& edgesWorld() const;
  const PointCloud& planesWorld() const;
  const std::vector<std::size_t>& assembledKeyframes() const;

  // The k nearest assembled edge / plane points of p_world, k = indices.size() (== sq_dists.size()), sorted by
  // distance; returns how many were found (fewer only when the cloud is smaller than k). sq_dists in [m^2].
  std::size_t nearestEdges(const Eigen::Vector3f& p_world, std::span<std::uint32_t> indices,
                           std::span<float> sq_dists) const;
  std::size_t nearestPlanes(const Eigen::Vector3f& p_world, std::span<std::uint32_t> indices,
                            std::span<float> sq_dists) const;

  std::size_t size() const;
  const Keyframe& keyframe(std::size_t index) const;  // throws std::invalid_argument when out of range
  std::vector<Eigen::Isometry3d> poses() const;       // T_world_lidar of every keyframe, by index

  // The full clouds of the given keyframes in the world frame, concatenated in the given order and then
  // voxel-downsampled with `leaf` [m] (0 keeps every point). For map export and loop-closure ICP. Throws
  // std::invalid_argument on a bad index.
  PointCloud fullCloudWorld(std::span<const std::size_t> indices, float leaf = 0.0f) const;

  const LocalMapConfig& config() const { return config_; }

 private:
  struct Impl;
  LocalMapConfig config_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drover::lidar
