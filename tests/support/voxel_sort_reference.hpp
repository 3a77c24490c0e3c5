#pragma once
// The local map's voxel downsampling as it was first written: a comparison sort of (voxel key, point index) pairs
// with the key offset into 21 bits per axis. Kept as the reference that lidar::detail::voxelDownsample must equal
// bit for bit (tests/lidar/test_local_map_voxel.cpp), and as the "before" of bench_local_map.
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "lidar/feature_set.hpp"

namespace drover::testing {

inline lidar::PointCloud voxelDownsampleBySort(const lidar::PointCloud& cloud, float leaf) {
  constexpr std::int64_t kHalfRange = std::int64_t{1} << 20;
  const float inv_leaf = 1.0f / leaf;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::uint64_t packed = 0;
    bool ok = cloud[i].allFinite();
    for (int axis = 0; axis < 3 && ok; ++axis) {
      const double cell = std::floor(static_cast<double>(cloud[i][axis]) * inv_leaf);
      ok = cell >= -static_cast<double>(kHalfRange) && cell < static_cast<double>(kHalfRange);
      if (ok) packed = (packed << 21) | static_cast<std::uint64_t>(static_cast<std::int64_t>(cell) + kHalfRange);
    }
    if (ok) keyed.emplace_back(packed, static_cast<std::uint32_t>(i));
  }
  // As it was: in parallel above 20,000 points (the pairs are distinct, so the order is the serial sort's).
  if (keyed.size() > 20'000) tbb::parallel_sort(keyed.begin(), keyed.end());
  else std::sort(keyed.begin(), keyed.end());
  lidar::PointCloud out;
  for (std::size_t begin = 0; begin < keyed.size();) {
    std::size_t end = begin;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (; end < keyed.size() && keyed[end].first == keyed[begin].first; ++end)
      sum += cloud[keyed[end].second].cast<double>();
    out.push_back((sum / static_cast<double>(end - begin)).cast<float>());
    begin = end;
  }
  return out;
}

}  // namespace drover::testing
