#pragma once
// Voxel-grid downsampling (PCL's VoxelGrid, which LIO-SAM applies with odometrySurfLeafSize and
// mappingCornerLeafSize): every point falls into the axis-aligned cube floor(p / leaf) and each occupied cube is
// replaced by the centroid of its points. Hash-based, O(n), no sort.
#include "lidar/feature_set.hpp"

namespace drover::lidar {

// Centroid per occupied voxel of edge `leaf` [m]. Output order is deterministic: voxels in the order their first
// point appears in `cloud` (so the same input always gives the same output, on any platform). Non-finite points
// are skipped; coordinates beyond +-2^30 leaves fall into the outermost voxel of the key range.
// Throws std::invalid_argument unless leaf is finite and > 0.
PointCloud voxelDownsample(const PointCloud& cloud, float leaf);

}  // namespace drover::lidar
