#include "lidar/scan_matcher.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "geometry/so3.hpp"
#include "lidar/scan_matcher_residual.hpp"

namespace drover::lidar {
namespace {

constexpr int kMaxNeighbors = 32;

// One scan point's correspondence: the feature, the weight multiplying its residual rows, and its distance when
// it was matched.
struct Match {
  detail::FeatureFit fit;
  double weight = 0.0;
  bool is_edge = false;
  bool fitted = false;  // a fit was computed for this point in this iteration
  bool reused = false;  // ... or taken from the previous one
};

double residualWeight(const ScanMatcherConfig& c, bool is_edge, double distance, double range) {
  if (c.kernel == RobustKernel::kHuber) {
    return distance <= c.huber_delta ? 1.0 : std::sqrt(c.huber_delta / distance);
  }
  // LIO-SAM cornerOptimization / surfOptimization; the plane term shrinks the penalty of far points, whose
  // plane noise grows with range.
  const double s = is_edge ? 1.0 - 0.9 * distance : 1.0 - 0.9 * distance / std::sqrt(std::max(range, 1e-9));
  return s > c.min_weight ? s : 0.0;
}

// A scan point's last fit and the neighbours (map indices, nearest first) it was fitted to. The fit depends on those
// points alone, and the map does not change during one align(): when the next iteration's search returns the
// same neighbours in the same order, the fit is the same to the bit and is reused. After the first iteration the
// pose moves by millimetres and most points keep their neighbours, so the eigen-decompositions, a fifth of the
// LIS's time on a car, are mostly skipped.
struct FitCache {
  std::array<std::uint32_t, kMaxNeighbors> neighbours{};
  detail::FeatureFit fit;
  bool filled = false;
};

Match matchPoint(const Eigen::Vector3f& p_lidar, bool is_edge, const Eigen::Isometry3d& T, const LocalMap& map,
                 const ScanMatcherConfig& c, FitCache& cache) {
  Match match;
  match.is_edge = is_edge;
  const Eigen::Vector3d p = p_lidar.cast<double>();
  const Eigen::Vector3f p_world = (T * p).cast<float>();
  std::array<std::uint32_t, kMaxNeighbors> idx{};
  std::array<float, kMaxNeighbors> sq{};
  const std::size_t k = static_cast<std::size_t>(c.neighbors);
  const std::size_t found = is_edge ? map.nearestEdges(p_world, {idx.data(), k}, {sq.data(), k})
                                    : map.nearestPlanes(p_world, {idx.data(), k}, {sq.data(), k});
  if (found < k || sq[k - 1] >= c.max_neighbor_distance * c.max_neighbor_distance) return match;
  if (c.reuse_fits && cache.filled && std::equal(idx.begin(), idx.begin() + k, cache.neighbours.begin())) {
    match.fit = cache.fit;
    match.reused = true;
  } else {
    const PointCloud& cloud = is_edge ? map.edgesWorld() : map.planesWorld();
    std::array<Eigen::Vector3d, kMaxNeighbors> neighbours;
    for (std::size_t i = 0; i < k; ++i) neighbours[i] = cloud[idx[i]].cast<double>();
    const int n = static_cast<int>(k);
    match.fit = is_edge ? detail::fitLine(neighbours.data(), n, c.edge_eigen_ratio)
                        : detail::fitPlane(neighbours.data(), n, c.plane_tolerance, c.plane_min_aspect);
    cache = {idx, match.fit, true};
    match.fitted = true;
  }
  if (!match.fit.valid) return match;
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 6> J;
  detail::residualAndJacobian(match.fit, T, p, r, J);
  match.weight = residualWeight(c, is_edge, r.norm(), p.norm());
  if (match.weight <= 0.0) match.fit.valid = false;
  return match;
}

// Correspondences of every scan point at T: edges first, then planes, each in its own slot.
// `fits` holds one FitCache per scan point (edges, then planes) across the iterations of one align().
std::vector<Match> findMatches(const FeatureSet& scan, const LocalMap& map, const Eigen::Isometry3d& T,
                               const ScanMatcherConfig& c, std::vector<FitCache>& fits) {
  const std::size_t n_edges = scan.edges.size();
  std::vector<Match> matches(n_edges + scan.planes.size());
  auto run = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const bool is_edge = i < n_edges;
      const Eigen::Vector3f& p = is_edge ? scan.edges[i] : scan.planes[i - n_edges];
      if (p.allFinite()) matches[i] = matchPoint(p, is_edge, T, map, c, fits[i]);
    }
  };
  if (c.parallel) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, matches.size(), 64),
                      [&](const tbb::blocked_range<std::size_t>& range) { run(range.begin(), range.end()); });
  } else {
    run(0, matches.size());
  }
  return matches;
}

// Weighted normal equations at T for fixed correspondences, summed in point order (deterministic).
struct NormalEquations {
  Matrix6d H = Matrix6d::Zero();  // sum (s J)^T (s J)
  Vector6d g = Vector6d::Zero();  // sum (s J)^T (s r)
  int edges = 0;
  int planes = 0;
  double squared_distance_sum = 0.0;  // [m^2] unweighted
};

NormalEquations accumulate(const FeatureSet& scan, const std::vector<Match>& matches, const Eigen::Isometry3d& T) {
  NormalEquations ne;
  const std::size_t n_edges = scan.edges.size();
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 6> J;
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const Match& m = matches[i];
    if (!m.fit.valid) continue;
    const Eigen::Vector3f& p = i < n_edges ? scan.edges[i] : scan.planes[i - n_edges];
    detail::residualAndJacobian(m.fit, T, p.cast<double>(), r, J);
    const Eigen::Vector2d rw = m.weight * r;
    const Eigen::Matrix<double, 2, 6> Jw = m.weight * J;
    ne.H.noalias() += Jw.transpose() * Jw;
    ne.g.noalias() += Jw.transpose() * rw;
    ne.squared_distance_sum += r.squaredNorm();
    (m.is_edge ? ne.edges : ne.planes) += 1;
  }
  return ne;
}

// Gauss-Newton step solved in the eigenbasis of H, keeping only the well-constrained directions (Zhang 2016).
Vector6d remappedStep(const NormalEquations& ne, const Eigen::SelfAdjointEigenSolver<Matrix6d>& eig,
                      double threshold) {
  Vector6d step = Vector6d::Zero();
  for (int i = 0; i < 6; ++i) {
    const double lambda = eig.eigenvalues()(i);
    if (lambda < threshold || lambda <= 0.0) continue;
    const Vector6d u = eig.eigenvectors().col(i);
    step -= u * (u.dot(ne.g) / lambda);
  }
  return step;
}

void fillStatistics(const ScanMatcherConfig& c, const NormalEquations& ne, MatchResult& result) {
  result.edge_inliers = ne.edges;
  result.plane_inliers = ne.planes;
  const int count = ne.edges + ne.planes;
  result.fitness = count > 0 ? std::sqrt(ne.squared_distance_sum / count) : 0.0;
  result.hessian = ne.H;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(ne.H);
  result.eigenvalues = eig.eigenvalues();
  const double sigma = std::max(result.fitness, c.sigma_floor);
  result.information = ne.H / (sigma * sigma);
  result.covariance.setZero();
  result.degenerate_directions.clear();
  const double threshold = c.degeneracyThreshold(count);
  for (int i = 0; i < 6; ++i) {
    const Vector6d u = eig.eigenvectors().col(i);
    const double lambda = eig.eigenvalues()(i);
    if (lambda < threshold || lambda <= 0.0) {
      result.degenerate_directions.push_back(u);
      result.covariance += c.degenerate_variance * u * u.transpose();
    } else {
      result.covariance += (sigma * sigma / lambda) * u * u.transpose();
    }
  }
  result.degenerate_count = static_cast<int>(result.degenerate_directions.size());
  result.degenerate = result.degenerate_count > 0;
}

// T (+) dxi = (R Exp(phi), t + R rho): the same first-order perturbation as T Exp(dxi), but a translation step
// is applied exactly along R rho, so a remapped step never leaks into a degenerate translation direction (with
// Exp on SE(3) the translation would be turned by J_l(phi)).
Eigen::Isometry3d retract(const Eigen::Isometry3d& T, const Vector6d& step) {
  Eigen::Isometry3d out = T;
  out.translation() += T.linear() * step.head<3>();
  out.linear() = T.linear() * geometry::expSO3(step.tail<3>());
  return out;
}

MatchResult notTried(const Eigen::Isometry3d& guess, MatchStatus status, std::string reason) {
  MatchResult result;
  result.T_world_lidar = guess;
  result.status = status;
  result.reason = std::move(reason);
  return result;
}

}  // namespace

const char* toString(MatchStatus status) {
  switch (status) {
    case MatchStatus::kConverged: return "converged";
    case MatchStatus::kMaxIterations: return "max iterations";
    case MatchStatus::kEmptyMap: return "empty map";
    case MatchStatus::kTooFewFeatures: return "too few features";
    case MatchStatus::kTooFewCorrespondences: return "too few correspondences";
  }
  return "unknown";
}

std::string ScanMatcherConfig::validate() const {
  if (max_iterations < 1) return "scan matcher max_iterations must be >= 1, got " + std::to_string(max_iterations);
  if (neighbors < 3 || neighbors > kMaxNeighbors) {
    return "scan matcher neighbors must be in [3, 32], got " + std::to_string(neighbors);
  }
  if (min_edge_features < 0 || min_plane_features < 0 || min_correspondences < 0) {
    return "scan matcher minimum counts must be >= 0";
  }
  for (const auto& [name, value] :
       {std::pair<const char*, double>{"convergence_translation", convergence_translation},
        {"convergence_rotation", convergence_rotation}, {"max_neighbor_distance", max_neighbor_distance},
        {"edge_eigen_ratio", edge_eigen_ratio}, {"plane_tolerance", plane_tolerance},
        {"huber_delta", huber_delta}, {"degeneracy_threshold", degeneracy_threshold},
        {"sigma_floor", sigma_floor}, {"degenerate_variance", degenerate_variance}}) {
    if (!std::isfinite(value) || value <= 0.0) {
      return std::string("scan matcher ") + name + " must be finite and > 0, got " + std::to_string(value);
    }
  }
  if (!std::isfinite(degeneracy_threshold_per_correspondence) || degeneracy_threshold_per_correspondence < 0.0) {
    return "scan matcher degeneracy_threshold_per_correspondence must be finite and >= 0, got " +
           std::to_string(degeneracy_threshold_per_correspondence);
  }
  if (!(plane_min_aspect >= 0.0 && plane_min_aspect < 1.0)) {
    return "scan matcher plane_min_aspect must be in [0, 1), got " + std::to_string(plane_min_aspect);
  }
  if (!(min_weight >= 0.0 && min_weight < 1.0)) {
    return "scan matcher min_weight must be in [0, 1), got " + std::to_string(min_weight);
  }
  return {};
}

double ScanMatcherConfig::degeneracyThreshold(int correspondences) const {
  return std::max(degeneracy_threshold, degeneracy_threshold_per_correspondence * std::max(correspondences, 0));
}

ScanMatcher::ScanMatcher(const ScanMatcherConfig& config) : config_(config) {
  if (const std::string error = config_.validate(); !error.empty()) {
    throw std::invalid_argument("ScanMatcher: " + error);
  }
}

MatchResult ScanMatcher::align(const FeatureSet& scan, const LocalMap& map,
                               const Eigen::Isometry3d& T_world_lidar_guess) const {
  const ScanMatcherConfig& c = config_;
  if (!T_world_lidar_guess.matrix().allFinite()) throw std::invalid_argument("ScanMatcher::align: non-finite guess");
  if (map.edgesWorld().empty() && map.planesWorld().empty()) {
    return notTried(T_world_lidar_guess, MatchStatus::kEmptyMap, "the local map has no points (build() it first)");
  }
  if (static_cast<int>(scan.edges.size()) < c.min_edge_features ||
      static_cast<int>(scan.planes.size()) < c.min_plane_features) {
    return notTried(T_world_lidar_guess, MatchStatus::kTooFewFeatures,
                    "scan has " + std::to_string(scan.edges.size()) + " edges and " +
                        std::to_string(scan.planes.size()) + " planes, needs " +
                        std::to_string(c.min_edge_features) + " and " + std::to_string(c.min_plane_features));
  }
  MatchResult result;
  Eigen::Isometry3d T = T_world_lidar_guess;
  std::vector<Match> matches;
  std::vector<FitCache> fits(scan.edges.size() + scan.planes.size());
  result.status = MatchStatus::kMaxIterations;
  while (result.iterations < c.max_iterations) {
    matches = findMatches(scan, map, T, c, fits);
    for (const Match& m : matches) {
      result.fits_computed += m.fitted;
      result.fits_reused += m.reused;
    }
    const NormalEquations ne = accumulate(scan, matches, T);
    if (ne.edges + ne.planes < c.min_correspondences) {
      return notTried(T_world_lidar_guess, MatchStatus::kTooFewCorrespondences,
                      "iteration " + std::to_string(result.iterations) + " found " +
                          std::to_string(ne.edges + ne.planes) + " correspondences, needs " +
                          std::to_string(c.min_correspondences));
    }
    const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(ne.H);
    const Vector6d step = remappedStep(ne, eig, c.degeneracyThreshold(ne.edges + ne.planes));
    T = retract(T, step);
    ++result.iterations;
    if (step.head<3>().norm() < c.convergence_translation && step.tail<3>().norm() < c.convergence_rotation) {
      result.status = MatchStatus::kConverged;
      break;
    }
  }
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  result.T_world_lidar = T;
  result.converged = result.status == MatchStatus::kConverged;
  fillStatistics(c, accumulate(scan, matches, T), result);
  char summary[160];
  std::snprintf(summary, sizeof(summary),
                "%s after %d iterations, %d edge and %d plane correspondences, fitness %.3g m%s",
                toString(result.status), result.iterations, result.edge_inliers, result.plane_inliers, result.fitness,
                result.degenerate ? ", degenerate" : "");
  result.reason = summary;
  return result;
}

}  // namespace drover::lidar
