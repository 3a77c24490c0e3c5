#include "lidar/local_map_voxel.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace drover::lidar::detail {
namespace {

constexpr double kHalfRange = double(std::int64_t{1} << 20);  // voxels per half axis that can be keyed
constexpr int kDigitBits = 11;                                 // radix digit: at most 2048 buckets
constexpr std::size_t kRadixFrom = 256;                        // points: below, a comparison sort is cheaper

struct Cell {
  std::int32_t x = 0, y = 0, z = 0;
};

// The voxel of one point; false when it cannot be keyed (beyond +-2^20 voxels, or non-finite).
bool voxelCell(const Eigen::Vector3f& p, float inv_leaf, Cell& cell) {
  std::array<std::int32_t, 3> c{};
  for (int axis = 0; axis < 3; ++axis) {
    const double v = std::floor(static_cast<double>(p[axis]) * inv_leaf);
    if (!(v >= -kHalfRange && v < kHalfRange)) return false;
    c[static_cast<std::size_t>(axis)] = static_cast<std::int32_t>(v);
  }
  cell = {c[0], c[1], c[2]};
  return true;
}

// The voxels of a cloud, packed relative to its bounding box: x-major, so ordering keys orders voxels by (x, y, z).
struct KeyPacking {
  Cell lo{std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::max(),
          std::numeric_limits<std::int32_t>::max()};
  Cell hi{std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::min(),
          std::numeric_limits<std::int32_t>::min()};
  int by = 0, bz = 0;

  void extend(const Cell& c) {
    lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
    hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
  }
  static int width(std::int32_t a, std::int32_t b) {
    return static_cast<int>(std::bit_width(static_cast<std::uint32_t>(b - a)));
  }
  int bits() {  // call once the box is complete
    by = width(lo.y, hi.y);
    bz = width(lo.z, hi.z);
    return width(lo.x, hi.x) + by + bz;
  }
  std::uint64_t key(const Cell& c) const {
    return (std::uint64_t(std::uint32_t(c.x - lo.x)) << (by + bz)) | (std::uint64_t(std::uint32_t(c.y - lo.y)) << bz) |
           std::uint64_t(std::uint32_t(c.z - lo.z));
  }
};

// Stable LSD radix sort of the words by their bits [from, from + bits), in as few passes of at most kDigitBits as
// they need. Sorting (key << from | index) words by the key bits alone, from input in ascending index order, orders
// them by (key, index). 8-byte words: the passes are memory-bound, so the fewer bytes the better (16-byte pairs, or
// the point carried along, measured slower here).
void radixSort(std::vector<std::uint64_t>& words, int from, int bits) {
  std::vector<std::uint64_t> buffer(words.size());
  const int passes = (bits + kDigitBits - 1) / kDigitBits;
  const int digit = passes > 0 ? (bits + passes - 1) / passes : 0;
  const std::uint64_t mask = (std::uint64_t{1} << digit) - 1;
  std::vector<std::size_t> start(std::size_t{1} << digit);
  for (int shift = from; shift < from + bits; shift += digit) {
    std::fill(start.begin(), start.end(), 0);
    for (const std::uint64_t w : words) ++start[(w >> shift) & mask];
    std::size_t offset = 0;
    for (std::size_t& s : start) offset += std::exchange(s, offset);
    for (const std::uint64_t w : words) buffer[start[(w >> shift) & mask]++] = w;
    words.swap(buffer);
  }
}

// Centroids of the runs of equal keys in entries sorted by (key, index): one point a voxel, each sum running over
// its points in ascending point order, so the result depends on the input alone.
template <class Entry, class KeyOf, class IndexOf>
void centroids(const PointCloud& cloud, const std::vector<Entry>& sorted, KeyOf key_of, IndexOf index_of,
               PointCloud& out) {
  for (std::size_t begin = 0; begin < sorted.size();) {
    const auto key = key_of(sorted[begin]);
    std::size_t end = begin;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (; end < sorted.size() && key_of(sorted[end]) == key; ++end) {
      const Eigen::Vector3f& p = cloud[static_cast<std::size_t>(index_of(sorted[end]))];
      sum += p.cast<double>();
    }
    out.push_back((sum / static_cast<double>(end - begin)).cast<float>());
    begin = end;
  }
}

// Clouds whose box and size need more than 64 bits (voxels kilometres apart at a fine leaf): keys and indices as
// pairs, compared.
void centroidsByPairs(const PointCloud& cloud, float inv_leaf, const KeyPacking& packing, PointCloud& out) {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    Cell c;
    if (voxelCell(cloud[i], inv_leaf, c)) keyed.emplace_back(packing.key(c), static_cast<std::uint32_t>(i));
  }
  std::sort(keyed.begin(), keyed.end());
  centroids(cloud, keyed, [](const auto& e) { return e.first; }, [](const auto& e) { return e.second; }, out);
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
  KeyPacking packing;
  std::size_t keyable = 0;
  for (const Eigen::Vector3f& p : cloud) {
    Cell c;
    if (!voxelCell(p, inv_leaf, c)) continue;
    packing.extend(c);
    ++keyable;
  }
  if (keyable == 0) return out;
  // A local map's box (~250 m x 60 m x 15 m at 0.4 m on a road) needs ~24 key bits, its ~4e5 points 19 index
  // bits: one 64-bit word per point, two radix passes over the key bits.
  const int key_bits = packing.bits();
  const int index_bits = std::max(1, static_cast<int>(std::bit_width(cloud.size() - 1)));
  if (key_bits + index_bits > 64) {
    centroidsByPairs(cloud, inv_leaf, packing, out);
    return out;
  }
  std::vector<std::uint64_t> words;
  words.reserve(keyable);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    Cell c;
    if (voxelCell(cloud[i], inv_leaf, c)) words.push_back((packing.key(c) << index_bits) | i);
  }
  // Sorted by (key, index), the centroid sums run in a fixed order: bit-identical output for equal input.
  if (words.size() < kRadixFrom) std::sort(words.begin(), words.end());
  else radixSort(words, index_bits, key_bits);
  const std::uint64_t index_mask = (std::uint64_t{1} << index_bits) - 1;
  centroids(cloud, words, [&](std::uint64_t w) { return w >> index_bits; },
            [&](std::uint64_t w) { return w & index_mask; }, out);
  return out;
}

}  // namespace drover::lidar::detail
