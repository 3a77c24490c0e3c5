#include "eval/rpe.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "eval/message.hpp"
#include "geometry/se3.hpp"

namespace drover::eval {

namespace {

// evo's filter_pairs_by_path on n positions given by an accessor.
template <typename Position>
IdPairs pathPairs(std::size_t n, const Position& position, double delta) {
  if (!(delta > 0.0) || !std::isfinite(delta))
    throw std::invalid_argument("RPE delta must be > 0 m, got " + shortNumber(delta));
  std::vector<std::size_t> ids;
  double path = 0.0;
  for (std::size_t i = 1; i < n; ++i) {
    path += (position(i) - position(i - 1)).norm();
    if (path >= delta) {
      ids.push_back(i);
      path = 0.0;
    }
  }
  IdPairs pairs;
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

}  // namespace

IdPairs pairsByIndex(std::size_t num_poses, std::size_t delta) {
  if (delta == 0) throw std::invalid_argument("RPE delta must be >= 1 frame");
  IdPairs pairs;
  for (std::size_t i = 0; i + delta < num_poses; i += delta) pairs.emplace_back(i, i + delta);
  return pairs;
}

IdPairs pairsByPath(const Trajectory& trajectory, double delta) {
  return pathPairs(
      trajectory.size(), [&](std::size_t i) { return Eigen::Vector3d(trajectory[i].T_world_body.translation()); },
      delta);
}

IdPairs pairsByPath(const Trajectory& trajectory, const std::vector<std::size_t>& indices, double delta) {
  return pathPairs(
      indices.size(),
      [&](std::size_t k) { return Eigen::Vector3d(trajectory.at(indices[k]).T_world_body.translation()); }, delta);
}

std::vector<double> relativeErrors(const Trajectory& ref, const std::vector<std::size_t>& ref_index,
                                   const Trajectory& est_aligned, const IdPairs& pairs, PoseRelation relation) {
  if (ref_index.size() != est_aligned.size())
    throw std::invalid_argument("RPE needs one reference index per estimated pose, got " +
                                std::to_string(ref_index.size()) + " and " + std::to_string(est_aligned.size()));
  std::vector<double> errors;
  errors.reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    if (i >= est_aligned.size() || j >= est_aligned.size()) throw std::invalid_argument("RPE pair index out of range");
    const Eigen::Isometry3d Q_rel =
        geometry::inverse(ref.at(ref_index[i]).T_world_body) * ref.at(ref_index[j]).T_world_body;
    const Eigen::Isometry3d P_rel = geometry::inverse(est_aligned[i].T_world_body) * est_aligned[j].T_world_body;
    errors.push_back(poseError(geometry::inverse(Q_rel) * P_rel, relation));
  }
  return errors;
}

namespace {

IdPairs selectPairs(const Trajectory& ref, const std::vector<std::size_t>& ref_index, const Trajectory& est_aligned,
                    const RpeOptions& o) {
  if (o.unit == DeltaUnit::kFrames) {
    if (!(o.delta >= 1.0) || o.delta != std::floor(o.delta) || o.delta > 1e15)
      throw std::invalid_argument("RPE delta in frames must be a positive integer, got " + shortNumber(o.delta));
    return pairsByIndex(est_aligned.size(), static_cast<std::size_t>(o.delta));
  }
  // evo measures the path on the aligned estimate (alignment happens before the pair search).
  return o.pairs_from_reference ? pairsByPath(ref, ref_index, o.delta) : pairsByPath(est_aligned, o.delta);
}

}  // namespace

RpeResult computeRpe(const Trajectory& ref, const Trajectory& est, const RpeOptions& options) {
  RpeResult r;
  r.relation = options.relation;
  static_cast<MatchedTrajectories&>(r) = matchAndAlign(ref, est, options.association, options.alignment);
  r.id_pairs = selectPairs(ref, r.association.first, r.est_aligned, options);
  if (r.id_pairs.empty())
    throw std::invalid_argument(
        "RPE delta = " + shortNumber(options.delta) + (options.unit == DeltaUnit::kFrames ? " frames" : " m") +
        " selects no pose pair among " + std::to_string(r.pairs) + " matched poses; try a smaller delta");
  r.errors = relativeErrors(ref, r.association.first, r.est_aligned, r.id_pairs, options.relation);
  r.stats = computeStatistics(r.errors);
  for (const auto& pair : r.id_pairs) r.times.push_back(r.est_aligned[pair.second].t);
  return r;
}

}  // namespace drover::eval
