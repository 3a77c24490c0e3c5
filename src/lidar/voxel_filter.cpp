#include "lidar/voxel_filter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace drover::lidar {
namespace {

constexpr double kKeyLimit = 1073741823.0;  // 2^30 - 1: voxel indices are clamped to +-this

struct VoxelKey {
  std::int32_t x, y, z;
  bool operator==(const VoxelKey&) const = default;
};

std::int32_t voxelIndex(float coordinate, double inv_leaf) {
  return static_cast<std::int32_t>(std::clamp(std::floor(coordinate * inv_leaf), -kKeyLimit, kKeyLimit));
}

// Large odd multipliers mix the three indices (as in Teschner et al. 2003's spatial hash), then a final
// avalanche so that the low bits used by the power-of-two table are well distributed.
std::uint64_t hashKey(const VoxelKey& k) {
  std::uint64_t h = static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.x)) * 0x9E3779B97F4A7C15ull;
  h ^= static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.y)) * 0xC2B2AE3D27D4EB4Full;
  h ^= static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.z)) * 0x165667B19E3779F9ull;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  return h ^ (h >> 32);
}

struct Accumulator {
  double x = 0, y = 0, z = 0;
  std::uint32_t count = 0;
};

}  // namespace

PointCloud voxelDownsample(const PointCloud& cloud, float leaf) {
  if (!std::isfinite(leaf) || leaf <= 0.0f)
    throw std::invalid_argument("voxelDownsample: leaf must be finite and > 0, got " + std::to_string(leaf));
  if (cloud.empty()) return {};
  const double inv_leaf = 1.0 / static_cast<double>(leaf);

  // Open addressing with linear probing; load factor <= 0.5. Slots hold an index into `cells` (-1 = empty).
  std::size_t capacity = 16;
  while (capacity < 2 * cloud.size()) capacity <<= 1;
  const std::size_t mask = capacity - 1;
  std::vector<std::int32_t> slots(capacity, -1);
  std::vector<VoxelKey> keys;
  std::vector<Accumulator> cells;
  keys.reserve(cloud.size() / 4 + 16);
  cells.reserve(cloud.size() / 4 + 16);

  for (const Eigen::Vector3f& p : cloud) {
    if (!p.allFinite()) continue;
    const VoxelKey key{voxelIndex(p.x(), inv_leaf), voxelIndex(p.y(), inv_leaf), voxelIndex(p.z(), inv_leaf)};
    std::size_t slot = hashKey(key) & mask;
    while (slots[slot] >= 0 && !(keys[static_cast<std::size_t>(slots[slot])] == key)) slot = (slot + 1) & mask;
    if (slots[slot] < 0) {
      slots[slot] = static_cast<std::int32_t>(cells.size());
      keys.push_back(key);
      cells.emplace_back();
    }
    Accumulator& a = cells[static_cast<std::size_t>(slots[slot])];
    a.x += p.x();
    a.y += p.y();
    a.z += p.z();
    ++a.count;
  }

  PointCloud out;
  out.reserve(cells.size());
  for (const Accumulator& a : cells) {
    const double n = a.count;
    out.emplace_back(static_cast<float>(a.x / n), static_cast<float>(a.y / n), static_cast<float>(a.z / n));
  }
  return out;
}

}  // namespace drover::lidar
