// BVH construction: binned surface-area heuristic (Wald, "On fast Construction of SAH-based Bounding Volume
// Hierarchies", 2007), flattened depth-first so the left child follows its parent in memory.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "sim/world_impl.hpp"

namespace drover::sim::detail {
namespace {

constexpr int kBins = 16;
constexpr std::uint32_t kMaxLeafSize = 4;
constexpr int kMaxDepth = 48;  // traversal's stack holds 128 entries; beyond this depth we split by median

struct Item {
  Aabb box;
  Eigen::Vector3d centroid;
  std::uint32_t prim;
};

// Float node bounds padded outward: 0.1 mm plus 1e-6 relative, far above float rounding of coordinates and of
// the slab distances (see World::intersect), so a float slab test never culls a primitive the double test hits.
void setNodeBounds(BvhNode& n, const Aabb& b) {
  for (int i = 0; i < 3; ++i) {
    const double pad_lo = 1e-4 + 1e-6 * std::abs(b.lo[i]), pad_hi = 1e-4 + 1e-6 * std::abs(b.hi[i]);
    n.bounds[i] = std::nextafter(static_cast<float>(b.lo[i] - pad_lo), -std::numeric_limits<float>::infinity());
    n.bounds[3 + i] = std::nextafter(static_cast<float>(b.hi[i] + pad_hi), std::numeric_limits<float>::infinity());
  }
}

class Builder {
 public:
  explicit Builder(std::vector<Item>& items) : items_(items) {}
  std::vector<BvhNode> nodes;

  void build(std::uint32_t begin, std::uint32_t end, int depth) {
    const std::uint32_t node = static_cast<std::uint32_t>(nodes.size());
    nodes.emplace_back();
    Aabb bounds, centroids;
    for (std::uint32_t i = begin; i < end; ++i) {
      bounds.grow(items_[i].box);
      centroids.grow(items_[i].centroid);
    }
    setNodeBounds(nodes[node], bounds);
    const std::uint32_t count = end - begin;
    if (count <= kMaxLeafSize) return makeLeaf(node, begin, count);
    const std::uint32_t mid = split(begin, end, bounds, centroids, depth);
    if (mid == begin || mid == end) return makeLeaf(node, begin, count);
    build(begin, mid, depth + 1);
    nodes[node].index = static_cast<std::uint32_t>(nodes.size());
    nodes[node].count = 0;
    build(mid, end, depth + 1);
  }

 private:
  std::vector<Item>& items_;

  void makeLeaf(std::uint32_t node, std::uint32_t begin, std::uint32_t count) {
    nodes[node].index = begin;
    nodes[node].count = count;
  }

  // Returns the partition point; begin or end means "make a leaf".
  std::uint32_t split(std::uint32_t begin, std::uint32_t end, const Aabb& bounds, const Aabb& centroids,
                      int depth) {
    int axis = 0;
    const Eigen::Vector3d extent = centroids.hi - centroids.lo;
    extent.maxCoeff(&axis);
    const std::uint32_t count = end - begin;
    if (extent[axis] <= 0.0) return count > 16 ? medianSplit(begin, end, axis) : begin;  // all centroids equal
    if (depth >= kMaxDepth) return medianSplit(begin, end, axis);

    const double lo = centroids.lo[axis], scale = kBins / extent[axis];
    const auto binOf = [&](const Item& it) {
      return std::min(kBins - 1, static_cast<int>((it.centroid[axis] - lo) * scale));
    };
    std::array<Aabb, kBins> bin_box;
    std::array<std::uint32_t, kBins> bin_count{};
    for (std::uint32_t i = begin; i < end; ++i) {
      const int b = binOf(items_[i]);
      bin_box[b].grow(items_[i].box);
      ++bin_count[b];
    }
    // Sweep from the right for suffix areas, then from the left evaluating each plane.
    std::array<double, kBins> right_area{};
    std::array<std::uint32_t, kBins> right_count{};
    Aabb acc;
    std::uint32_t n = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.grow(bin_box[b]);
      n += bin_count[b];
      right_area[b] = acc.halfArea();
      right_count[b] = n;
    }
    double best_cost = std::numeric_limits<double>::infinity();
    int best_plane = -1;
    Aabb left;
    std::uint32_t left_count = 0;
    for (int b = 1; b < kBins; ++b) {
      left.grow(bin_box[b - 1]);
      left_count += bin_count[b - 1];
      if (left_count == 0 || right_count[b] == 0) continue;
      const double cost = left.halfArea() * left_count + right_area[b] * right_count[b];
      if (cost < best_cost) best_cost = cost, best_plane = b;
    }
    const double parent_area = std::max(bounds.halfArea(), 1e-300);
    const double split_cost = 1.0 + best_cost / parent_area;  // traversal step + expected primitive tests
    if (best_plane < 0) return medianSplit(begin, end, axis);
    if (split_cost >= count && count <= 2 * kMaxLeafSize) return begin;
    const auto it = std::partition(items_.begin() + begin, items_.begin() + end,
                                   [&](const Item& item) { return binOf(item) < best_plane; });
    return static_cast<std::uint32_t>(it - items_.begin());
  }

  std::uint32_t medianSplit(std::uint32_t begin, std::uint32_t end, int axis) {
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end,
                     [axis](const Item& a, const Item& b) { return a.centroid[axis] < b.centroid[axis]; });
    return mid;
  }
};

}  // namespace

Aabb primitiveBounds(const Primitive& p) {
  Aabb b;
  switch (p.kind) {
    case PrimKind::kBox: {
      const Eigen::Vector3d e = p.R_world_local.cwiseAbs() * p.half;
      b.lo = p.center - e;
      b.hi = p.center + e;
      break;
    }
    case PrimKind::kCylinder:
      b.lo = p.center - Eigen::Vector3d(p.half[0], p.half[0], 0.0);
      b.hi = p.center + Eigen::Vector3d(p.half[0], p.half[0], p.half[2]);
      break;
    case PrimKind::kRectangle: {
      const Eigen::Vector3d e =
          p.R_world_local.col(0).cwiseAbs() * p.half[0] + p.R_world_local.col(1).cwiseAbs() * p.half[1];
      b.lo = p.center - e;
      b.hi = p.center + e;
      break;
    }
  }
  return b;
}

std::vector<BvhNode> buildBvh(std::vector<Primitive>& prims) {
  if (prims.empty()) return {};
  std::vector<Item> items(prims.size());
  for (std::uint32_t i = 0; i < prims.size(); ++i) {
    items[i].box = primitiveBounds(prims[i]);
    items[i].centroid = 0.5 * (items[i].box.lo + items[i].box.hi);
    items[i].prim = i;
  }
  Builder builder(items);
  builder.nodes.reserve(2 * prims.size());
  builder.build(0, static_cast<std::uint32_t>(items.size()), 0);
  std::vector<Primitive> ordered;
  ordered.reserve(prims.size());
  for (const Item& it : items) ordered.push_back(prims[it.prim]);
  prims = std::move(ordered);
  return std::move(builder.nodes);
}

}  // namespace drover::sim::detail
