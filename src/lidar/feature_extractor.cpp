#include "lidar/feature_extractor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "lidar/voxel_filter.hpp"

namespace drover::lidar {
namespace {

// Per-point label during selection (LIO-SAM's cloudNeighborPicked and cloudLabel in one byte).
enum Label : std::uint8_t { kFree = 0, kRejected = 1, kSuppressed = 2, kEdge = 3 };

// The valid points grouped by ring (ring r in [begin[r], begin[r + 1])), each ring in firing order.
struct RingCloud {
  std::vector<Eigen::Vector3f> xyz;   // [m], lidar frame at the sweep start
  std::vector<float> range;           // [m]
  std::vector<std::uint8_t> far_next; // 1: the next point of the ring is more than max_column_gap columns away
  std::vector<std::size_t> begin;
};

bool isValid(const LidarPoint& p, double min2, double max2, ExtractionStats& stats) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    ++stats.non_finite;
    return false;
  }
  const double r2 = double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z;
  if (r2 < min2 || r2 > max2) {
    ++stats.out_of_range;
    return false;
  }
  return true;
}

// Indices of the valid points, grouped by ring (counting sort, stable), optionally time-ordered within each ring.
std::vector<std::uint32_t> orderByRing(const LidarScan& scan, const FeatureExtractorConfig& config,
                                       ExtractionStats& stats, std::vector<std::size_t>& begin) {
  const double min2 = config.min_range * config.min_range, max2 = config.max_range * config.max_range;
  std::vector<std::uint8_t> valid(scan.points.size());
  std::size_t rings = 0;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    valid[i] = isValid(scan.points[i], min2, max2, stats);
    if (valid[i]) rings = std::max<std::size_t>(rings, scan.points[i].ring + 1u);
  }
  begin.assign(rings + 1, 0);
  for (std::size_t i = 0; i < scan.points.size(); ++i)
    if (valid[i]) ++begin[scan.points[i].ring + 1u];
  for (std::size_t r = 0; r < rings; ++r) begin[r + 1] += begin[r];
  std::vector<std::uint32_t> order(begin.back());
  std::vector<std::size_t> next(begin.begin(), begin.end() - 1);
  for (std::size_t i = 0; i < scan.points.size(); ++i)
    if (valid[i]) order[next[scan.points[i].ring]++] = static_cast<std::uint32_t>(i);
  if (!config.sort_by_time || !scan.has_time) return order;
  const auto by_time = [&](std::uint32_t a, std::uint32_t b) {
    return scan.points[a].time_offset < scan.points[b].time_offset;
  };
  for (std::size_t r = 0; r < rings; ++r) {
    const auto first = order.begin() + static_cast<std::ptrdiff_t>(begin[r]);
    const auto last = order.begin() + static_cast<std::ptrdiff_t>(begin[r + 1]);
    if (!std::is_sorted(first, last, by_time)) std::stable_sort(first, last, by_time);
  }
  return order;
}

RingCloud groupByRing(const LidarScan& scan, const FeatureExtractorConfig& config, ExtractionStats& stats) {
  RingCloud cloud;
  const std::vector<std::uint32_t> order = orderByRing(scan, config, stats, cloud.begin);
  const std::size_t n = order.size();
  cloud.xyz.resize(n);
  cloud.range.resize(n);
  cloud.far_next.assign(n, 1);
  std::vector<Eigen::Vector2f> heading(n);  // unit horizontal direction (zero for a point straight up or down)
  for (std::size_t k = 0; k < n; ++k) {
    const LidarPoint& p = scan.points[order[k]];
    cloud.xyz[k] = Eigen::Vector3f(p.x, p.y, p.z);
    cloud.range[k] = cloud.xyz[k].norm();
    const float h = std::hypot(p.x, p.y);
    heading[k] = h > 1e-6f ? Eigen::Vector2f(p.x / h, p.y / h) : Eigen::Vector2f::Zero();
  }
  // Azimuth gap > max_column_gap columns <=> cos(gap) < cos(max_column_gap * 2 pi / columns).
  const double max_gap = config.max_column_gap * 2 * std::numbers::pi / config.columns;
  const float cos_max_gap = max_gap >= std::numbers::pi ? -1.0f : static_cast<float>(std::cos(max_gap));
  for (std::size_t r = 0; r + 1 < cloud.begin.size(); ++r)
    for (std::size_t k = cloud.begin[r]; k + 1 < cloud.begin[r + 1]; ++k)
      cloud.far_next[k] = heading[k].dot(heading[k + 1]) < cos_max_gap;
  return cloud;
}

// LIO-SAM calculateSmoothness over the ring's interior [b + w, e - w).
void computeCurvature(const RingCloud& c, std::size_t b, std::size_t e, std::size_t w, std::vector<float>& curvature) {
  for (std::size_t i = b + w; i + w < e; ++i) {
    // sum_{j != i} (r_j - r_i) = sum over the whole window - (2w + 1) r_i
    float sum = -static_cast<float>(2 * w + 1) * c.range[i];
    for (std::size_t j = i - w; j <= i + w; ++j) sum += c.range[j];
    curvature[i] = sum * sum;
  }
}

// LIO-SAM markOccludedPoints, within one ring: the far side of a depth step between neighbouring columns (it may be
// hidden in the next sweep), and points whose range jumps on both sides (a surface parallel to the beam).
void markRejected(const RingCloud& c, std::size_t b, std::size_t e, const FeatureExtractorConfig& config,
                  std::vector<std::uint8_t>& label) {
  const std::size_t w = static_cast<std::size_t>(config.half_window);
  for (std::size_t i = b + w; i + w < e; ++i) {
    if (i + 1 + w < e && !c.far_next[i]) {
      const float d1 = c.range[i], d2 = c.range[i + 1];
      if (d1 - d2 > config.occlusion_depth_gap) {
        for (std::size_t j = i - w; j <= i; ++j) label[j] = kRejected;
      } else if (d2 - d1 > config.occlusion_depth_gap) {
        for (std::size_t j = i + 1; j <= std::min(i + 1 + w, e - 1); ++j) label[j] = kRejected;
      }
    }
    const float limit = config.parallel_ratio * c.range[i];
    if (std::abs(c.range[i - 1] - c.range[i]) > limit && std::abs(c.range[i + 1] - c.range[i]) > limit)
      label[i] = kRejected;
  }
}

// Bars the neighbours of a picked edge on both sides, stopping at a column gap (LIO-SAM's neighbour picking).
void suppressNeighbours(const RingCloud& c, std::size_t b, std::size_t e, std::size_t i, int radius,
                        std::vector<std::uint8_t>& label) {
  for (std::size_t j = i + 1; j < e && j <= i + radius && !c.far_next[j - 1]; ++j)
    if (label[j] == kFree) label[j] = kSuppressed;
  for (std::size_t j = i; j > b && i - (j - 1) <= static_cast<std::size_t>(radius) && !c.far_next[j - 1]; --j)
    if (label[j - 1] == kFree) label[j - 1] = kSuppressed;
}

// Edges then flat points of one sub-region [sp, ep) of a ring [b, e).
void selectInRegion(const RingCloud& c, std::size_t b, std::size_t e, std::size_t sp, std::size_t ep,
                    const FeatureExtractorConfig& config, const std::vector<float>& curvature,
                    std::vector<std::uint8_t>& label, std::vector<std::uint32_t>& scratch, PointCloud& edges,
                    PointCloud& planes) {
  scratch.clear();
  for (std::size_t k = sp; k < ep; ++k)
    if (label[k] == kFree && curvature[k] > config.edge_threshold) scratch.push_back(static_cast<std::uint32_t>(k));
  std::sort(scratch.begin(), scratch.end(), [&](std::uint32_t a, std::uint32_t b2) {
    return curvature[a] > curvature[b2] || (curvature[a] == curvature[b2] && a < b2);
  });
  int picked = 0;
  for (std::uint32_t k : scratch) {
    if (picked >= config.max_edges_per_region) break;
    if (label[k] != kFree) continue;
    label[k] = kEdge;
    edges.push_back(c.xyz[k]);
    ++picked;
    suppressNeighbours(c, b, e, k, config.suppression_radius, label);
  }
  for (std::size_t k = sp; k < ep; ++k)
    if (label[k] != kRejected && label[k] != kEdge && curvature[k] < config.surf_threshold) planes.push_back(c.xyz[k]);
}

PointCloud downsampled(PointCloud cloud, float leaf) { return leaf > 0 ? voxelDownsample(cloud, leaf) : cloud; }

}  // namespace

std::string FeatureExtractorConfig::validate() const {
  if (columns < 1) return "columns must be >= 1, got " + std::to_string(columns);
  if (!std::isfinite(min_range) || min_range < 0) return "min_range must be >= 0, got " + std::to_string(min_range);
  if (!(max_range > min_range)) return "max_range must exceed min_range, got " + std::to_string(max_range);
  if (half_window < 1 || half_window > 50) return "half_window must be in [1, 50], got " + std::to_string(half_window);
  if (!std::isfinite(edge_threshold) || !std::isfinite(surf_threshold) || surf_threshold < 0 ||
      edge_threshold < surf_threshold)
    return "need 0 <= surf_threshold <= edge_threshold, got " + std::to_string(surf_threshold) + " and " +
           std::to_string(edge_threshold);
  if (sub_regions < 1) return "sub_regions must be >= 1, got " + std::to_string(sub_regions);
  if (max_edges_per_region < 0) return "max_edges_per_region must be >= 0, got " + std::to_string(max_edges_per_region);
  if (suppression_radius < 0) return "suppression_radius must be >= 0, got " + std::to_string(suppression_radius);
  if (max_column_gap < 0) return "max_column_gap must be >= 0, got " + std::to_string(max_column_gap);
  if (!std::isfinite(occlusion_depth_gap) || occlusion_depth_gap <= 0)
    return "occlusion_depth_gap must be > 0, got " + std::to_string(occlusion_depth_gap);
  if (!std::isfinite(parallel_ratio) || parallel_ratio <= 0)
    return "parallel_ratio must be > 0, got " + std::to_string(parallel_ratio);
  for (float leaf : {edge_leaf, surf_leaf, full_leaf})
    if (!std::isfinite(leaf) || leaf < 0) return "voxel leaves must be finite and >= 0, got " + std::to_string(leaf);
  return {};
}

FeatureExtractor::FeatureExtractor(const FeatureExtractorConfig& config) : config_(config) {
  const std::string error = config.validate();
  if (!error.empty()) throw std::invalid_argument("FeatureExtractor: invalid config: " + error);
}

Extraction FeatureExtractor::extract(const LidarScan& deskewed) const {
  if (!deskewed.has_ring)
    throw std::invalid_argument("FeatureExtractor::extract: the scan has no rings (has_ring == false); "
                                "call inferRings() first");
  Extraction out;
  out.features.t = deskewed.t;
  out.stats.input_points = deskewed.points.size();
  const RingCloud cloud = groupByRing(deskewed, config_, out.stats);
  const std::size_t n = cloud.xyz.size();
  out.stats.valid_points = n;
  if (n == 0) {
    out.status = ExtractionStatus::kEmpty;
    return out;
  }
  std::vector<float> curvature(n, 0.0f);
  std::vector<std::uint8_t> label(n, kFree);
  std::vector<std::uint32_t> scratch;
  PointCloud edges, planes;
  const std::size_t w = static_cast<std::size_t>(config_.half_window);
  bool any_ring_used = false;
  for (std::size_t r = 0; r + 1 < cloud.begin.size(); ++r) {
    const std::size_t b = cloud.begin[r], e = cloud.begin[r + 1];
    if (e - b < 2 * w + 1) continue;
    any_ring_used = true;
    computeCurvature(cloud, b, e, w, curvature);
    markRejected(cloud, b, e, config_, label);
    const std::size_t first = b + w, interior = e - w - first;
    const std::size_t parts = static_cast<std::size_t>(config_.sub_regions);
    for (std::size_t j = 0; j < parts; ++j)
      selectInRegion(cloud, b, e, first + interior * j / parts, first + interior * (j + 1) / parts, config_,
                     curvature, label, scratch, edges, planes);
  }
  out.stats.rejected = static_cast<std::size_t>(std::count(label.begin(), label.end(), kRejected));
  out.stats.edges_raw = edges.size();
  out.stats.planes_raw = planes.size();
  if (!any_ring_used) out.status = ExtractionStatus::kTooFewPoints;
  out.features.edges = downsampled(std::move(edges), config_.edge_leaf);
  out.features.planes = downsampled(std::move(planes), config_.surf_leaf);
  out.features.full = downsampled(cloud.xyz, config_.full_leaf);
  return out;
}

}  // namespace drover::lidar
