#pragma once
// Point clouds as the lidar odometry passes them between its stages.
#include <Eigen/Core>
#include <vector>

#include "types/time.hpp"

namespace drover::lidar {

// Points [m] in one frame, named where the cloud is held (e.g. `PointCloud edges_lidar`).
using PointCloud = std::vector<Eigen::Vector3f>;

// LOAM features of one deskewed sweep, in the lidar frame at the sweep's start time `t` (LIO-SAM's convention:
// every point is moved to where the lidar was when the sweep began).
struct FeatureSet {
  Time t = 0;              // [ns] sweep start, the time the features (and the pose estimated from them) refer to
  PointCloud edges;        // sharp points (high curvature), downsampled
  PointCloud planes;       // flat points (low curvature), downsampled
  PointCloud full;         // every valid deskewed point, downsampled (for the map file and ICP)
};

// [bytes] the clouds' storage (what a keyframe costs in memory).
inline std::size_t featureBytes(const FeatureSet& f) {
  return (f.edges.capacity() + f.planes.capacity() + f.full.capacity()) * sizeof(Eigen::Vector3f);
}

}  // namespace drover::lidar
