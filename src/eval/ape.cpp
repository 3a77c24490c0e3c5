#include "eval/ape.hpp"

#include <cstdio>
#include <stdexcept>
#include <string>

#include "geometry/se3.hpp"

namespace drover::eval {

namespace {

std::string seconds(Time ns) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.9g s", toSeconds(ns));
  return buf;
}

}  // namespace

Association associateForEvaluation(const Trajectory& ref, const Trajectory& est, const AssociationOptions& options) {
  if (ref.empty()) throw std::invalid_argument("the reference trajectory is empty");
  if (est.empty()) throw std::invalid_argument("the estimated trajectory is empty");
  Association a = associate(ref, est, options);
  if (a.size() == 0)
    throw std::invalid_argument("found no matching timestamps between reference and estimate with max. time diff " +
                                seconds(options.max_diff) + " and time offset " + seconds(options.offset));
  return a;
}

std::vector<double> absoluteErrors(const Trajectory& ref, const std::vector<std::size_t>& ref_index,
                                   const Trajectory& est_aligned, PoseRelation relation) {
  if (ref_index.size() != est_aligned.size())
    throw std::invalid_argument("APE needs one reference index per estimated pose, got " +
                                std::to_string(ref_index.size()) + " and " + std::to_string(est_aligned.size()));
  std::vector<double> errors(est_aligned.size());
  for (std::size_t k = 0; k < est_aligned.size(); ++k) {
    const Eigen::Isometry3d& P_ref = ref.at(ref_index[k]).T_world_body;
    const Eigen::Isometry3d& P_est = est_aligned[k].T_world_body;
    if (relation == PoseRelation::kTranslation) {
      errors[k] = (P_est.translation() - P_ref.translation()).norm();
    } else {
      errors[k] = poseError(geometry::inverse(P_ref) * P_est, relation);
    }
  }
  return errors;
}

MatchedTrajectories matchAndAlign(const Trajectory& ref, const Trajectory& est, const AssociationOptions& association,
                                  Alignment alignment) {
  MatchedTrajectories m;
  m.alignment = alignment;
  m.association = associateForEvaluation(ref, est, association);
  m.pairs = m.association.size();
  m.max_pairs = m.association.max_pairs;
  m.alignment_transform = alignTrajectory(est, m.association.second, ref, m.association.first, alignment, m.est_aligned);
  return m;
}

ApeResult computeApe(const Trajectory& ref, const Trajectory& est, const ApeOptions& options) {
  ApeResult r;
  r.relation = options.relation;
  static_cast<MatchedTrajectories&>(r) = matchAndAlign(ref, est, options.association, options.alignment);
  r.errors = absoluteErrors(ref, r.association.first, r.est_aligned, options.relation);
  r.stats = computeStatistics(r.errors);
  r.times.reserve(r.pairs);
  for (const StampedPose& p : r.est_aligned) r.times.push_back(p.t);
  return r;
}

}  // namespace drover::eval
