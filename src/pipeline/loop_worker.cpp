#include "pipeline/loop_worker.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace drover::pipeline {

LoopWorker::LoopWorker(const LoopClosureConfig& loop, const lidar::LocalMapConfig& map) : map_(map), loops_(loop) {}

std::optional<LoopCorrection> LoopWorker::add(const KeyframeRecord& kf) {
  if (kf.index != map_.size())
    throw std::invalid_argument(fmt::format("loop worker: keyframe {} given, {} expected", kf.index, map_.size()));
  const Eigen::Isometry3d T_world_lidar =
      kf.index == 0 ? kf.T_world_lidar : map_.keyframe(kf.index - 1).T_world_lidar * kf.T_previous_this;
  map_.addSharedKeyframe(kf.features, T_world_lidar);  // the LIS's own clouds, not a copy
  // After the search, as the in-line loop closure does, and also when the search throws (the System goes on with
  // the next keyframe): the retired clouds are not kept here.
  const auto retire = [&] {
    for (std::size_t k = 0; k < kf.retired.size(); ++k) {
      map_.retire(kf.retired[k]);
      loops_.retire(kf.retired[k], kf.retired_by.at(k));
    }
  };
  std::optional<LoopCorrection> c;
  try {
    c = search(kf);
  } catch (...) {
    retire();
    throw;
  }
  retire();
  return c;
}

std::optional<LoopCorrection> LoopWorker::search(const KeyframeRecord& kf) {
  if (!loops_.addKeyframe(map_, kf.index, kf.degenerate_cov)) return std::nullopt;
  LoopCorrection c;
  c.poses = loops_.poses();
  for (const Eigen::Isometry3d& T : c.poses)  // never hand the LIS a pose it would refuse (the graph guards this)
    if (!T.matrix().allFinite()) throw std::runtime_error("loop worker: the pose graph gave a non-finite pose");
  for (std::size_t i = 0; i < c.poses.size(); ++i) map_.updatePose(i, c.poses[i]);
  c.event = loops_.events().back();
  return c;
}

std::size_t LoopWorker::keyframeBytes() const {
  std::size_t bytes = 0;
  for (std::size_t i = 0; i < map_.size(); ++i)  // those the LIS no longer holds (none while it runs)
    if (map_.keyframe(i).shared.use_count() == 1) bytes += lidar::featureBytes(map_.keyframe(i).features());
  return bytes;
}

}  // namespace drover::pipeline
