#pragma once
// Absolute pose error as evo_ape: associate by time, optionally align the estimate to the reference (Umeyama
// SE(3)/Sim(3) on positions), then E_i = P_ref,i^-1 P_est,i and a scalar error per pose (see pose_error.hpp).
#include <cstddef>
#include <vector>

#include "eval/association.hpp"
#include "eval/pose_error.hpp"
#include "eval/stats.hpp"
#include "eval/umeyama.hpp"
#include "types/trajectory.hpp"

namespace drover::eval {

struct ApeOptions {
  PoseRelation relation = PoseRelation::kTranslation;
  Alignment alignment = Alignment::kNone;
  AssociationOptions association;  // reference first, estimate second (evo: traj_ref, traj_est)
};

// Reference and estimate matched by time and the estimate aligned: the first step of APE and RPE.
struct MatchedTrajectories {
  Alignment alignment = Alignment::kNone;
  Sim3 alignment_transform;    // est -> ref; identity for kNone
  std::size_t pairs = 0;       // matched pose pairs
  std::size_t max_pairs = 0;   // the shorter trajectory's length
  Association association;     // pair k: ref[association.first[k]] with est[association.second[k]]
  Trajectory est_aligned;      // est_aligned[k]: the matched estimate pose k after alignment (for plots)
};

// Throws as associateForEvaluation and alignTrajectory do.
MatchedTrajectories matchAndAlign(const Trajectory& ref, const Trajectory& est, const AssociationOptions& association,
                                  Alignment alignment);

struct ApeResult : MatchedTrajectories {
  ErrorStatistics stats;
  std::vector<double> errors;  // one per matched pair, in the unit of relationUnit(relation)
  std::vector<Time> times;     // the estimate's stamps of the matched pairs [ns]
  PoseRelation relation = PoseRelation::kTranslation;
};

// Throws std::invalid_argument when no pose pairs match, or when alignment is asked for and the matched
// positions are degenerate (fewer than 3 non-collinear).
ApeResult computeApe(const Trajectory& ref, const Trajectory& est, const ApeOptions& options = {});

// Errors of matched poses: est_aligned[k] against ref[ref_index[k]]. kTranslation is |t_est - t_ref| as evo
// computes it.
std::vector<double> absoluteErrors(const Trajectory& ref, const std::vector<std::size_t>& ref_index,
                                   const Trajectory& est_aligned, PoseRelation relation);

// associate() for evaluation: throws std::invalid_argument for an empty trajectory or when no pair matches
// (the message names max_diff and offset).
Association associateForEvaluation(const Trajectory& ref, const Trajectory& est, const AssociationOptions& options);

}  // namespace drover::eval
