#pragma once
// Private helper of LocalMap: voxel-grid downsampling to the centroid of each occupied voxel (PCL VoxelGrid's
// semantics, which LIO-SAM's mappingCornerLeafSize / mappingSurfLeafSize filters use). Kept private to the local
// map so it does not compete with the front end's voxel filter; the output order is deterministic (voxels sorted
// by key), whatever the input order within a voxel.
#include "lidar/feature_set.hpp"

namespace drover::lidar::detail {

// Returns one point per occupied cube of side `leaf` [m] (the centroid of the points in it). Non-finite points
// are dropped; leaf <= 0 returns the finite points unchanged. Points beyond +-2^20 voxels from the origin are
// dropped (they cannot be keyed; at 0.2 m that is 200 km).
PointCloud voxelDownsample(const PointCloud& cloud, float leaf);

}  // namespace drover::lidar::detail
