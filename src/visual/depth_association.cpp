// LVI-SAM depth association (see depth_association.hpp): spherical grid, k-d tree on the unit sphere (nanoflann),
// ray-plane intersection with the three nearest lidar points.
#include "visual/depth_association.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nanoflann.hpp>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

namespace drover::visual {

namespace {

struct SphereCloud {  // nanoflann dataset adaptor over unit vectors
  std::vector<Eigen::Vector3f> unit;
  std::vector<Eigen::Vector3d> point;  // camera frame [m]
  std::vector<double> range;
  std::size_t kdtree_get_point_count() const { return unit.size(); }
  float kdtree_get_pt(std::uint32_t i, std::size_t d) const { return unit[i][static_cast<int>(d)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox& /*bb*/) const {
    return false;
  }
};
constexpr std::size_t kCandidates = 8;  // neighbours searched for a well-shaped triangle
constexpr double kMinSine = 0.3;         // sine of the smallest angle at the nearest point accepted (~17 deg)
using SphereTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, SphereCloud>, SphereCloud,
                                                       3, std::uint32_t>;

std::vector<Eigen::Vector3d> voxelDownsample(const std::vector<Eigen::Vector3d>& points, double voxel) {
  std::vector<Eigen::Vector3d> out;
  if (voxel <= 0) {
    for (const auto& p : points)
      if (p.allFinite()) out.push_back(p);
    return out;
  }
  // One point per voxel: the centroid (as PCL's VoxelGrid).
  struct Acc {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int n = 0;
  };
  std::unordered_map<std::uint64_t, Acc> cells;
  std::vector<std::uint64_t> order;
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    const auto key = [&](int i) { return static_cast<std::uint64_t>(std::floor(p[i] / voxel) + (1 << 20)) & 0x1FFFFF; };
    const std::uint64_t k = key(0) | (key(1) << 21) | (key(2) << 42);
    Acc& a = cells[k];
    if (a.n == 0) order.push_back(k);
    a.sum += p;
    ++a.n;
  }
  out.reserve(order.size());
  for (std::uint64_t k : order) out.push_back(cells[k].sum / cells[k].n);
  return out;
}

}  // namespace

std::string DepthAssociationConfig::validate() const {
  if (!(window_s > 0)) return "window_s must be > 0 s, got " + std::to_string(window_s);
  if (!(voxel_size >= 0)) return "voxel_size must be >= 0 m, got " + std::to_string(voxel_size);
  if (!(grid_resolution_deg > 0 && grid_resolution_deg <= 10))
    return "grid_resolution_deg must be in (0, 10], got " + std::to_string(grid_resolution_deg);
  if (!(neighbour_cells > 0)) return "neighbour_cells must be > 0, got " + std::to_string(neighbour_cells);
  if (!(max_depth_spread > 0)) return "max_depth_spread must be > 0 m, got " + std::to_string(max_depth_spread);
  if (!(min_depth > 0 && max_depth > min_depth))
    return "need 0 < min_depth < max_depth, got " + std::to_string(min_depth) + ", " + std::to_string(max_depth);
  if (!(min_incidence_cos >= 0 && min_incidence_cos < 1))
    return "min_incidence_cos must be in [0, 1), got " + std::to_string(min_incidence_cos);
  return {};
}

DepthAssociator::DepthAssociator(const DepthAssociationConfig& config) : config_(config) {
  if (const std::string error = config.validate(); !error.empty())
    throw std::invalid_argument("DepthAssociationConfig: " + error);
}

void DepthAssociator::addSweep(Time t, const std::vector<Eigen::Vector3d>& points_world) {
  if (!sweeps_.empty() && t < sweeps_.back().t)
    throw std::invalid_argument("DepthAssociator::addSweep: time " + std::to_string(t) + " ns before " +
                                std::to_string(sweeps_.back().t) + " ns");
  sweeps_.push_back({t, voxelDownsample(points_world, config_.voxel_size)});
  const Time window = static_cast<Time>(config_.window_s * 1e9);
  while (!sweeps_.empty() && sweeps_.front().t < t - window) sweeps_.pop_front();
}

DepthAssociationResult DepthAssociator::associate(Time t, const Eigen::Isometry3d& T_world_cam,
                                                  const std::vector<Eigen::Vector2d>& normalized) const {
  DepthAssociationResult result;
  result.features.resize(normalized.size());
  // 1. Points in the camera frame, nearest per spherical cell (removes points hidden behind nearer ones).
  const double res = config_.grid_resolution_deg * std::numbers::pi / 180.0;
  const int bins = static_cast<int>(std::ceil(std::numbers::pi / res));
  std::vector<double> cell_range(static_cast<std::size_t>(bins) * bins, std::numeric_limits<double>::infinity());
  std::vector<Eigen::Vector3d> cell_point(cell_range.size());
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  const Time window = static_cast<Time>(config_.window_s * 1e9);
  // Only points that can be a feature's neighbour matter: those within the features' normalised bounding box
  // widened by the neighbour angle (and never beyond LVI-SAM's view cut |x|, |y| <= 10 z). This skips the
  // trigonometry for the ~80 % of the window's points outside the camera's view.
  double max_x = 0, max_y = 0;
  for (const Eigen::Vector2d& n : normalized) {
    max_x = std::max(max_x, std::abs(n.x()));
    max_y = std::max(max_y, std::abs(n.y()));
  }
  const double margin = std::tan(std::min(1.2, 2 * config_.neighbour_cells * res));
  const double cut_x = std::min(10.0, (max_x + margin) / std::max(1e-3, 1 - max_x * margin));
  const double cut_y = std::min(10.0, (max_y + margin) / std::max(1e-3, 1 - max_y * margin));
  for (const Sweep& sweep : sweeps_) {
    if (sweep.t > t || sweep.t < t - window) continue;
    for (const Eigen::Vector3d& pw : sweep.points_world) {
      const Eigen::Vector3d p = T_cam_world * pw;
      if (p.z() <= 0 || std::abs(p.x()) > cut_x * p.z() || std::abs(p.y()) > cut_y * p.z()) continue;
      const double azimuth = std::atan2(p.x(), p.z()), elevation = std::atan2(p.y(), std::hypot(p.x(), p.z()));
      const int col = static_cast<int>(std::floor((azimuth + std::numbers::pi / 2) / res));
      const int row = static_cast<int>(std::floor((elevation + std::numbers::pi / 2) / res));
      if (col < 0 || row < 0 || col >= bins || row >= bins) continue;
      const std::size_t cell = static_cast<std::size_t>(row) * bins + col;
      const double range = p.norm();
      if (range < cell_range[cell]) {
        cell_range[cell] = range;
        cell_point[cell] = p;
      }
    }
  }
  SphereCloud sphere;
  for (std::size_t c = 0; c < cell_range.size(); ++c) {
    if (!std::isfinite(cell_range[c]) || cell_range[c] <= 0) continue;
    sphere.unit.push_back((cell_point[c] / cell_range[c]).cast<float>());
    sphere.point.push_back(cell_point[c]);
    sphere.range.push_back(cell_range[c]);
  }
  result.points_used = sphere.unit.size();
  if (sphere.unit.size() < 3) {
    result.no_neighbours = static_cast<int>(normalized.size());
    return result;
  }
  const SphereTree tree(3, sphere, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  // Chord length on the unit sphere of `neighbour_cells` cells (LVI-SAM: (sin(bin) * 5)^2 on squared distances).
  const double max_chord = 2 * std::sin(std::min(std::numbers::pi / 2, config_.neighbour_cells * res) / 2);
  for (std::size_t i = 0; i < normalized.size(); ++i) {
    FeatureDepth& out = result.features[i];
    const Eigen::Vector3d ray = Eigen::Vector3d(normalized[i].x(), normalized[i].y(), 1.0).normalized();
    const Eigen::Vector3f query = ray.cast<float>();
    std::uint32_t index[kCandidates];
    float sq_dist[kCandidates];
    const std::size_t found = tree.knnSearch(query.data(), kCandidates, index, sq_dist);
    std::size_t within = 0;
    while (within < found && sq_dist[within] <= max_chord * max_chord) ++within;
    if (within < 3) {
      out.status = DepthStatus::kNoNeighbours;
      ++result.no_neighbours;
      continue;
    }
    // The two nearest and the next one not collinear with them: on a regular scan pattern the three nearest are
    // often on one scan line, whose "plane" is undetermined across it.
    Eigen::Vector3d p[3] = {sphere.point[index[0]], sphere.point[index[1]], {}};
    double r_min = std::min(sphere.range[index[0]], sphere.range[index[1]]);
    double r_max = std::max(sphere.range[index[0]], sphere.range[index[1]]);
    std::size_t third = 2;
    const Eigen::Vector3d e1 = (p[1] - p[0]).normalized();
    while (third < within && e1.cross((sphere.point[index[third]] - p[0]).normalized()).norm() < kMinSine) ++third;
    if (third == within) {
      out.status = DepthStatus::kGrazing;
      ++result.rejected_grazing;
      continue;
    }
    p[2] = sphere.point[index[third]];
    r_min = std::min(r_min, sphere.range[index[third]]);
    r_max = std::max(r_max, sphere.range[index[third]]);
    if (r_max - r_min > config_.max_depth_spread) {
      out.status = DepthStatus::kDiscontinuity;
      ++result.rejected_discontinuity;
      continue;
    }
    // Ray s * ray meets the plane n . x = n . p0 at s = (n . p0) / (n . ray).
    const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]);
    const double n_norm = n.norm(), n_dot_ray = n.dot(ray);
    if (!(n_norm > 0) || std::abs(n_dot_ray) < config_.min_incidence_cos * n_norm) {
      out.status = DepthStatus::kGrazing;
      ++result.rejected_grazing;
      continue;
    }
    const double s = n.dot(p[0]) / n_dot_ray;  // range along the ray [m]
    if (s < r_min - config_.max_depth_spread || s > r_max + config_.max_depth_spread) {  // far extrapolation
      out.status = DepthStatus::kGrazing;
      ++result.rejected_grazing;
      continue;
    }
    const double depth = s * ray.z();
    if (!(depth >= config_.min_depth && depth <= config_.max_depth)) {
      out.status = DepthStatus::kOutOfRange;
      ++result.rejected_range;
      continue;
    }
    out.status = DepthStatus::kOk;
    out.depth = depth;
    out.spread = r_max - r_min;
    ++result.associated;
  }
  return result;
}

void DepthAssociator::reanchor(const Eigen::Isometry3d& T_new_old) {
  for (Sweep& sweep : sweeps_)
    for (Eigen::Vector3d& p : sweep.points_world) p = T_new_old * p;
}

}  // namespace drover::visual
