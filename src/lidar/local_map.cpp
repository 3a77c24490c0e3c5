#include "lidar/local_map.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

#include "lidar/local_map_kdtree.hpp"
#include "lidar/local_map_voxel.hpp"

namespace drover::lidar {
namespace {

PointCloud transformCloud(const PointCloud& cloud_lidar, const Eigen::Isometry3d& T_world_lidar) {
  const Eigen::Matrix3f R = T_world_lidar.linear().cast<float>();
  const Eigen::Vector3f t = T_world_lidar.translation().cast<float>();
  PointCloud out;
  out.reserve(cloud_lidar.size());
  for (const auto& p : cloud_lidar) out.push_back(R * p + t);
  return out;
}

std::string checkNonNegative(const char* name, double value) {
  if (!std::isfinite(value) || value < 0.0) {
    return std::string("local map ") + name + " must be finite and >= 0, got " + std::to_string(value);
  }
  return {};
}

}  // namespace

std::string LocalMapConfig::validate() const {
  if (!std::isfinite(surrounding_radius) || surrounding_radius <= 0.0) {
    return "local map surrounding_radius must be finite and > 0 m, got " + std::to_string(surrounding_radius);
  }
  if (!std::isfinite(edge_leaf) || edge_leaf <= 0.0) {
    return "local map edge_leaf must be finite and > 0 m, got " + std::to_string(edge_leaf);
  }
  if (!std::isfinite(plane_leaf) || plane_leaf <= 0.0) {
    return "local map plane_leaf must be finite and > 0 m, got " + std::to_string(plane_leaf);
  }
  for (const auto& [name, value] : {std::pair<const char*, double>{"keyframe_density", keyframe_density},
                                    {"recent_window", recent_window},
                                    {"full_leaf", full_leaf},
                                    {"retire_radius", retire_radius},
                                    {"retire_age", retire_age}}) {
    if (std::string error = checkNonNegative(name, value); !error.empty()) return error;
  }
  if (recent_count < 0) return "local map recent_count must be >= 0, got " + std::to_string(recent_count);
  if (cache_capacity < 1) return "local map cache_capacity must be >= 1, got " + std::to_string(cache_capacity);
  return {};
}

// World-frame copies of one keyframe's edges and planes, stamped with the build that last used them.
struct CachedKeyframe {
  PointCloud edges_world;
  PointCloud planes_world;
  std::uint64_t last_used = 0;
};

struct LocalMap::Impl {
  std::vector<Keyframe> keyframes;
  std::unordered_map<std::size_t, CachedKeyframe> cache;
  std::uint64_t build_count = 0;
  std::uint64_t pose_version = 0;        // bumped by updatePose: a reused selection must still reassemble
  std::uint64_t assembled_version = ~0ull;
  std::vector<std::size_t> assembled;
  PointCloud edges_world;
  PointCloud planes_world;
  std::unique_ptr<detail::CloudKdTree> edge_tree;
  std::unique_ptr<detail::CloudKdTree> plane_tree;
  std::size_t retired = 0;

  const Keyframe& at(std::size_t index) const {
    if (index >= keyframes.size()) {
      throw std::invalid_argument("LocalMap: keyframe index " + std::to_string(index) + " out of range (size " +
                                  std::to_string(keyframes.size()) + ")");
    }
    return keyframes[index];
  }
};

LocalMap::LocalMap(const LocalMapConfig& config) : config_(config), impl_(std::make_unique<Impl>()) {
  if (const std::string error = config_.validate(); !error.empty()) {
    throw std::invalid_argument("LocalMap: " + error);
  }
  impl_->edge_tree = std::make_unique<detail::CloudKdTree>(impl_->edges_world);
  impl_->plane_tree = std::make_unique<detail::CloudKdTree>(impl_->planes_world);
}

LocalMap::~LocalMap() = default;
LocalMap::LocalMap(LocalMap&&) noexcept = default;
LocalMap& LocalMap::operator=(LocalMap&&) noexcept = default;

std::size_t LocalMap::addKeyframe(const FeatureSet& features, const Eigen::Isometry3d& T_world_lidar) {
  if (!T_world_lidar.matrix().allFinite()) throw std::invalid_argument("LocalMap::addKeyframe: non-finite pose");
  auto stored = std::make_shared<FeatureSet>();
  stored->t = features.t;
  stored->edges = detail::voxelDownsample(features.edges, static_cast<float>(config_.edge_leaf));
  stored->planes = detail::voxelDownsample(features.planes, static_cast<float>(config_.plane_leaf));
  stored->full = detail::voxelDownsample(features.full, static_cast<float>(config_.full_leaf));
  return addSharedKeyframe(std::move(stored), T_world_lidar);
}

std::size_t LocalMap::addSharedKeyframe(std::shared_ptr<const FeatureSet> downsampled,
                                        const Eigen::Isometry3d& T_world_lidar) {
  if (!downsampled) throw std::invalid_argument("LocalMap::addSharedKeyframe: no features");
  if (!T_world_lidar.matrix().allFinite()) throw std::invalid_argument("LocalMap::addKeyframe: non-finite pose");
  Keyframe keyframe;
  keyframe.index = impl_->keyframes.size();
  keyframe.t = downsampled->t;
  keyframe.T_world_lidar = T_world_lidar;
  keyframe.shared = std::move(downsampled);
  impl_->keyframes.push_back(std::move(keyframe));
  return impl_->keyframes.size() - 1;
}

void LocalMap::updatePose(std::size_t index, const Eigen::Isometry3d& T_world_lidar) {
  impl_->at(index);
  if (!T_world_lidar.matrix().allFinite()) throw std::invalid_argument("LocalMap::updatePose: non-finite pose");
  impl_->keyframes[index].T_world_lidar = T_world_lidar;
  impl_->cache.erase(index);
  ++impl_->pose_version;
}

std::vector<std::size_t> LocalMap::supersededBy(std::size_t index) const {
  const Keyframe& newer = impl_->at(index);
  std::vector<std::size_t> out;
  if (config_.retire_radius <= 0.0) return out;
  const Time latest = newer.t - fromSeconds(config_.retire_age);
  const Eigen::Vector3d p = newer.T_world_lidar.translation();
  for (std::size_t i = 0; i < index && impl_->keyframes[i].t <= latest; ++i) {
    const Keyframe& older = impl_->keyframes[i];
    if (!older.retired && (older.T_world_lidar.translation() - p).norm() <= config_.retire_radius) out.push_back(i);
  }
  return out;
}

void LocalMap::retire(std::size_t index) {
  impl_->at(index);
  Keyframe& kf = impl_->keyframes[index];
  if (kf.retired) return;
  auto empty = std::make_shared<FeatureSet>();
  empty->t = kf.t;
  kf.shared = std::move(empty);
  kf.retired = true;
  ++impl_->retired;
  impl_->cache.erase(index);
}

std::size_t LocalMap::retiredCount() const { return impl_->retired; }

std::size_t LocalMap::cacheBytes() const {
  std::size_t bytes = 0;
  for (const auto& [index, entry] : impl_->cache)
    bytes += (entry.edges_world.capacity() + entry.planes_world.capacity()) * sizeof(Eigen::Vector3f);
  return bytes;
}

namespace {

// Surrounding keyframes thinned to the newest per density cube, plus the recent ones; ascending indices.
std::vector<std::size_t> selectKeyframes(const std::vector<Keyframe>& keyframes, const LocalMapConfig& config,
                                         const Eigen::Vector3d& center, std::size_t first) {
  std::vector<std::size_t> selected;
  if (keyframes.size() <= first) return selected;
  std::map<std::tuple<std::int64_t, std::int64_t, std::int64_t>, std::size_t> newest_per_cell;
  for (std::size_t k = first; k < keyframes.size(); ++k) {
    const Keyframe& kf = keyframes[k];
    const Eigen::Vector3d p = kf.T_world_lidar.translation();
    if (kf.retired || (p - center).norm() > config.surrounding_radius) continue;
    if (config.keyframe_density <= 0.0) {
      selected.push_back(kf.index);
      continue;
    }
    const Eigen::Vector3d cell = (p / config.keyframe_density).array().floor();
    newest_per_cell[{static_cast<std::int64_t>(cell.x()), static_cast<std::int64_t>(cell.y()),
                     static_cast<std::int64_t>(cell.z())}] = kf.index;  // ascending loop: the newest wins
  }
  for (const auto& [cell, index] : newest_per_cell) selected.push_back(index);
  const Keyframe& newest = keyframes.back();
  for (std::size_t i = first; i < keyframes.size(); ++i) {
    const bool in_window = config.recent_window > 0.0 &&
                           toSeconds(newest.t - keyframes[i].t) <= config.recent_window;
    const bool in_count = i + static_cast<std::size_t>(config.recent_count) >= keyframes.size();
    if ((in_window || in_count) && !keyframes[i].retired) selected.push_back(i);
  }
  std::sort(selected.begin(), selected.end());
  selected.erase(std::unique(selected.begin(), selected.end()), selected.end());
  return selected;
}

}  // namespace

LocalMapBuild LocalMap::build(const Eigen::Vector3d& center_world, std::size_t first_keyframe) {
  if (!center_world.allFinite()) throw std::invalid_argument("LocalMap::build: non-finite centre");
  Impl& m = *impl_;
  LocalMapBuild result;
  result.keyframes = selectKeyframes(m.keyframes, config_, center_world, first_keyframe);
  const std::uint64_t stamp = ++m.build_count;
  if (result.keyframes == m.assembled && m.assembled_version == m.pose_version) {
    for (std::size_t index : result.keyframes) m.cache[index].last_used = stamp;
    result.edge_points = m.edges_world.size();
    result.plane_points = m.planes_world.size();
    result.reused = true;
    return result;
  }
  // Transform the keyframes missing from the cache in parallel; each task writes only its own entry.
  std::vector<std::size_t> missing;
  for (std::size_t index : result.keyframes) {
    if (!m.cache.contains(index)) missing.push_back(index);
  }
  std::vector<CachedKeyframe*> slots;
  for (std::size_t index : missing) slots.push_back(&m.cache[index]);
  tbb::parallel_for(std::size_t{0}, missing.size(), [&](std::size_t i) {
    const Keyframe& kf = m.keyframes[missing[i]];
    slots[i]->edges_world = transformCloud(kf.features().edges, kf.T_world_lidar);
    slots[i]->planes_world = transformCloud(kf.features().planes, kf.T_world_lidar);
  });
  result.transformed = missing.size();

  PointCloud edges, planes;
  for (std::size_t index : result.keyframes) {
    CachedKeyframe& entry = m.cache[index];
    entry.last_used = stamp;
    edges.insert(edges.end(), entry.edges_world.begin(), entry.edges_world.end());
    planes.insert(planes.end(), entry.planes_world.begin(), entry.planes_world.end());
  }
  // The trees point at the clouds: drop them before the clouds change. Edges and planes are independent (each its
  // own cloud and tree): built side by side, the rebuild a keyframe triggers takes ~the planes' time alone.
  m.edge_tree.reset();
  m.plane_tree.reset();
  tbb::parallel_invoke(
      [&] {
        m.edges_world = detail::voxelDownsample(edges, static_cast<float>(config_.edge_leaf));
        m.edge_tree = std::make_unique<detail::CloudKdTree>(m.edges_world);
      },
      [&] {
        m.planes_world = detail::voxelDownsample(planes, static_cast<float>(config_.plane_leaf));
        m.plane_tree = std::make_unique<detail::CloudKdTree>(m.planes_world);
      });
  m.assembled = result.keyframes;
  m.assembled_version = m.pose_version;
  result.edge_points = m.edges_world.size();
  result.plane_points = m.planes_world.size();

  // Bound the cache: evict the least recently used entries that are not part of this local map.
  if (m.cache.size() > static_cast<std::size_t>(config_.cache_capacity)) {
    std::vector<std::pair<std::uint64_t, std::size_t>> stale;
    for (const auto& [index, entry] : m.cache) {
      if (entry.last_used != stamp) stale.emplace_back(entry.last_used, index);
    }
    std::sort(stale.begin(), stale.end());
    for (const auto& [used, index] : stale) {
      if (m.cache.size() <= static_cast<std::size_t>(config_.cache_capacity)) break;
      m.cache.erase(index);
    }
  }
  return result;
}

const PointCloud& LocalMap::edgesWorld() const { return impl_->edges_world; }
const PointCloud& LocalMap::planesWorld() const { return impl_->planes_world; }
const std::vector<std::size_t>& LocalMap::assembledKeyframes() const { return impl_->assembled; }

std::size_t LocalMap::nearestEdges(const Eigen::Vector3f& p_world, std::span<std::uint32_t> indices,
                                   std::span<float> sq_dists) const {
  if (indices.size() != sq_dists.size()) throw std::invalid_argument("LocalMap::nearestEdges: span sizes differ");
  return impl_->edge_tree->knn(p_world, indices.size(), indices.data(), sq_dists.data());
}

std::size_t LocalMap::nearestPlanes(const Eigen::Vector3f& p_world, std::span<std::uint32_t> indices,
                                    std::span<float> sq_dists) const {
  if (indices.size() != sq_dists.size()) throw std::invalid_argument("LocalMap::nearestPlanes: span sizes differ");
  return impl_->plane_tree->knn(p_world, indices.size(), indices.data(), sq_dists.data());
}

std::size_t LocalMap::size() const { return impl_->keyframes.size(); }
const Keyframe& LocalMap::keyframe(std::size_t index) const { return impl_->at(index); }

std::vector<Eigen::Isometry3d> LocalMap::poses() const {
  std::vector<Eigen::Isometry3d> out;
  out.reserve(impl_->keyframes.size());
  for (const auto& kf : impl_->keyframes) out.push_back(kf.T_world_lidar);
  return out;
}

PointCloud LocalMap::fullCloudWorld(std::span<const std::size_t> indices, float leaf) const {
  PointCloud out;
  for (std::size_t index : indices) {
    const Keyframe& kf = impl_->at(index);
    const PointCloud world = transformCloud(kf.features().full, kf.T_world_lidar);
    out.insert(out.end(), world.begin(), world.end());
  }
  return leaf > 0.0f ? detail::voxelDownsample(out, leaf) : out;
}

}  // namespace drover::lidar
