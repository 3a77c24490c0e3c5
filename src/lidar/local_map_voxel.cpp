#include "lidar/local_map_voxel.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

namespace drover::lidar::detail {
namespace {

constexpr std::size_t kParallelSort = 20'000;  // points: below, a thread's start-up costs more than it saves
constexpr std::int64_t kHalfRange = std::int64_t{1} << 20;  // 21 bits per axis, offset to be non-negative

bool voxelKey(const Eigen::Vector3f& p, float inv_leaf, std::uint64_t& key) {
  std::uint64_t packed = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double cell = std::floor(static_cast<double>(p[axis]) * inv_leaf);
    if (!(cell >= -static_cast<double>(kHalfRange) && cell < static_cast<double>(kHalfRange))) return false;
    packed = (packed << 21) | static_cast<std::uint64_t>(static_cast<std::int64_t>(cell) + kHalfRange);
  }
  key = packed;
  return true;
}

}  // namespace

PointCloud voxelDownsample(const PointCloud& cloud, float leaf) {
  PointCloud out;
  if (!(leaf > 0.0f)) {
    out.reserve(cloud.size());
    for (const auto& p : cloud) {
      if (p.allFinite()) out.push_back(p);
    }
    return out;
  }
  const float inv_leaf = 1.0f / leaf;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  keyed.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::uint64_t key = 0;
    if (cloud[i].allFinite() && voxelKey(cloud[i], inv_leaf, key)) {
      keyed.emplace_back(key, static_cast<std::uint32_t>(i));
    }
  }
  // Sorting by (key, index) makes the centroid sums run in a fixed order: bit-identical output for equal input
  // (the pairs are distinct, so the parallel sort gives the same order as a serial one). A local map's rebuild
  // sorts ~10^5 points: in parallel above kParallelSort.
  if (keyed.size() > kParallelSort) tbb::parallel_sort(keyed.begin(), keyed.end());
  else std::sort(keyed.begin(), keyed.end());
  for (std::size_t begin = 0; begin < keyed.size();) {
    std::size_t end = begin;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    while (end < keyed.size() && keyed[end].first == keyed[begin].first) {
      sum += cloud[keyed[end].second].cast<double>();
      ++end;
    }
    out.push_back((sum / static_cast<double>(end - begin)).cast<float>());
    begin = end;
  }
  return out;
}

}  // namespace drover::lidar::detail
