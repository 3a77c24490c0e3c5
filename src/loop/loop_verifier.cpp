#include "loop/loop_verifier.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace drover::loop {

std::string LoopVerifierConfig::validate() const {
  if (std::string e = matcher.validate(); !e.empty()) return "matcher: " + e;
  if (std::string e = submap.validate(); !e.empty()) return "submap: " + e;
  const double positive[] = {max_fitness, max_correction_translation, max_correction_rotation, sigma_floor_position,
                             sigma_floor_rotation};
  for (double v : positive)
    if (!std::isfinite(v) || v <= 0) return "max_fitness, max_correction_* and sigma_floor_* must be finite and > 0";
  if (min_inliers < 0) return "min_inliers must be >= 0";
  if (!std::isfinite(sigma_fitness_reference) || sigma_fitness_reference < 0)
    return "sigma_fitness_reference must be finite and >= 0";
  if (!(min_inlier_ratio >= 0 && min_inlier_ratio <= 1)) return "min_inlier_ratio must be in [0, 1]";
  return {};
}

geometry::Matrix6d LoopVerification::information() const {
  const geometry::Matrix6d information = covariance.inverse();
  return 0.5 * (information + information.transpose());
}

LoopVerifier::LoopVerifier(const LoopVerifierConfig& config) : config_(config), matcher_(config.matcher) {
  if (std::string e = config.validate(); !e.empty()) throw std::invalid_argument("loop verifier: " + e);
}

namespace {

// Matcher covariance (right perturbation [rho; phi] of T_candidate_query) -> covariance of the decoupled error
// [dp; dphi] with dp in the candidate frame: to first order T Exp([rho; phi]) = (R Exp(phi), t + R rho), so
// dp = R rho, dphi = phi. Then the floors are added and the result inverted.
void setCovariance(const lidar::MatchResult& r, const LoopVerifierConfig& c, LoopVerification& v) {
  geometry::Matrix6d J = geometry::Matrix6d::Identity();
  J.topLeftCorner<3, 3>() = r.T_world_lidar.linear();
  geometry::Matrix6d cov = J * r.covariance * J.transpose();
  cov = 0.5 * (cov + cov.transpose());
  cov.topLeftCorner<3, 3>().diagonal().array() += c.sigma_floor_position * c.sigma_floor_position;
  cov.bottomRightCorner<3, 3>().diagonal().array() += c.sigma_floor_rotation * c.sigma_floor_rotation;
  if (c.sigma_fitness_reference > 0 && r.fitness > c.sigma_fitness_reference)
    cov *= (r.fitness / c.sigma_fitness_reference) * (r.fitness / c.sigma_fitness_reference);
  v.covariance = cov;
}

std::string rejection(const LoopVerification& v, const lidar::MatchResult& r, const LoopVerifierConfig& c) {
  if (!r.converged) return "match did not converge: " + r.reason;
  if (r.degenerate) return fmt::format("match degenerate in {} directions", r.degenerate_count);
  if (v.fitness > c.max_fitness) return fmt::format("fitness {:.3f} m > {:.3f} m", v.fitness, c.max_fitness);
  if (v.inliers < c.min_inliers) return fmt::format("{} inliers < {}", v.inliers, c.min_inliers);
  if (v.inlier_ratio < c.min_inlier_ratio)
    return fmt::format("inlier ratio {:.2f} < {:.2f}", v.inlier_ratio, c.min_inlier_ratio);
  if (v.correction_translation > c.max_correction_translation || v.correction_rotation > c.max_correction_rotation)
    return fmt::format("solution {:.2f} m / {:.1f} deg from the guess (limits {:.2f} m / {:.1f} deg)",
                       v.correction_translation, v.correction_rotation * 180 / std::numbers::pi,
                       c.max_correction_translation, c.max_correction_rotation * 180 / std::numbers::pi);
  return {};
}

}  // namespace

LoopVerification LoopVerifier::verify(const lidar::FeatureSet& query, std::span<const SubmapKeyframe> submap,
                                      std::size_t candidate, const Eigen::Isometry3d& T_candidate_query_guess) const {
  if (submap.empty()) throw std::invalid_argument("loop verifier: empty submap");
  if (candidate >= submap.size())
    throw std::invalid_argument(
        fmt::format("loop verifier: candidate {} outside the submap of {}", candidate, submap.size()));
  if (!T_candidate_query_guess.matrix().allFinite()) throw std::invalid_argument("loop verifier: non-finite guess");
  const Eigen::Isometry3d T_candidate_world = submap[candidate].T_world_lidar.inverse();
  // Every submap keyframe is kept (no radius or density selection): the caller chose them.
  lidar::LocalMapConfig submap_config = config_.submap;
  submap_config.surrounding_radius = 1e6;
  submap_config.keyframe_density = 0.0;
  lidar::LocalMap map(submap_config);
  for (const SubmapKeyframe& k : submap) {
    if (!k.features) throw std::invalid_argument("loop verifier: submap keyframe without features");
    map.addKeyframe(*k.features, T_candidate_world * k.T_world_lidar);
  }
  map.build(Eigen::Vector3d::Zero());
  const lidar::MatchResult r = matcher_.align(query, map, T_candidate_query_guess);

  LoopVerification v;
  v.T_candidate_query = r.T_world_lidar;
  v.match_status = lidar::toString(r.status);
  v.converged = r.converged;
  v.degenerate = r.degenerate;
  v.iterations = r.iterations;
  v.fitness = r.fitness;
  v.inliers = r.edge_inliers + r.plane_inliers;
  const std::size_t features = query.edges.size() + query.planes.size();
  v.inlier_ratio = features ? static_cast<double>(v.inliers) / static_cast<double>(features) : 0.0;
  const Eigen::Isometry3d correction = T_candidate_query_guess.inverse() * r.T_world_lidar;
  v.correction_translation = correction.translation().norm();
  v.correction_rotation = Eigen::AngleAxisd(correction.linear()).angle();
  setCovariance(r, config_, v);
  const std::string why = rejection(v, r, config_);
  v.accepted = why.empty();
  v.reason = v.accepted ? fmt::format("accepted: fitness {:.3f} m, {} inliers ({:.0f} %), {} iterations", v.fitness,
                                      v.inliers, 100 * v.inlier_ratio, v.iterations)
                        : "rejected: " + why;
  return v;
}

}  // namespace drover::loop
