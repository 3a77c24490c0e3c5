#pragma once
// Loop closure away from the LIS (LIO-SAM's loopClosureThread): the keyframes the LIS made (KeyframeRecord, in
// order) go into a keyframe store and a LoopClosure of the worker's own, so the search and the verification never
// touch the LIS's map while it matches. Each keyframe's pose in the store is the previous one's times the LIS's
// relative motion between them, so a correction the worker made is carried by the keyframes that follow it, as the
// in-line loop closure's are. Accepted loops come back as a LoopCorrection for LidarOdometry::applyLoopCorrection.
// Not thread-safe by itself: pipeline::System calls it from its loop thread only.
#include <optional>

#include "lidar/local_map.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "pipeline/loop_closure.hpp"

namespace drover::pipeline {

class LoopWorker {
 public:
  // Throws std::invalid_argument when a config is invalid.
  LoopWorker(const LoopClosureConfig& loop, const lidar::LocalMapConfig& map);

  // The next keyframe (indices 0, 1, 2, ... in order, else std::invalid_argument). Returns the corrected poses
  // of keyframes 0..index when it closed a loop. The keyframes it retired are retired here after its search.
  std::optional<LoopCorrection> add(const KeyframeRecord& keyframe);

  std::size_t keyframes() const { return map_.size(); }
  // [bytes] the keyframes' feature clouds only it holds (it shares the LIS's: 0 while the LIS lives)
  std::size_t keyframeBytes() const;
  const LoopClosure& loopClosure() const { return loops_; }
  // The VIS's relative yaw for the shift search (LoopClosure::setVisualYawPrior); call before the first add().
  void setVisualYawPrior(VisualYawPrior prior) { loops_.setVisualYawPrior(std::move(prior)); }

 private:
  std::optional<LoopCorrection> search(const KeyframeRecord& keyframe);
  lidar::LocalMap map_;
  LoopClosure loops_;
};

}  // namespace drover::pipeline
