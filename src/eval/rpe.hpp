#pragma once
// Relative pose error as evo_rpe with consecutive pairs (all_pairs = False):
//   E_ij = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j),  Q: reference, P: estimate (after the optional alignment).
// Pairs (evo filters.filter_pairs_by_index / filter_pairs_by_path):
//   frames: ids 0, d, 2d, ... and the consecutive pairs of them;
//   meters: walking the path, an id is taken at the first pose where the path accumulated since the last id
//           (or since pose 0) reaches >= d, then the accumulator restarts; pose 0 is not an id itself.
// Like evo, the meter ids come from the ESTIMATE's path by default (evo_rpe's --pairs_from_reference switches
// to the reference).
#include <cstddef>
#include <utility>
#include <vector>

#include "eval/ape.hpp"

namespace drover::eval {

enum class DeltaUnit { kFrames, kMeters };

struct RpeOptions {
  PoseRelation relation = PoseRelation::kTranslation;
  double delta = 1.0;  // [frames] (a positive integer) or [m] (> 0)
  DeltaUnit unit = DeltaUnit::kFrames;
  bool pairs_from_reference = false;  // meters only: measure the path on the reference instead of the estimate
  Alignment alignment = Alignment::kNone;
  AssociationOptions association;
};

using IdPairs = std::vector<std::pair<std::size_t, std::size_t>>;

// MatchedTrajectories::pairs counts the matched poses before the delta selection.
struct RpeResult : MatchedTrajectories {
  ErrorStatistics stats;
  std::vector<double> errors;  // one per pair
  std::vector<Time> times;     // the estimate's stamp at the second pose j of each pair [ns]
  IdPairs id_pairs;            // indices k into the matched pairs (see association)
  PoseRelation relation = PoseRelation::kTranslation;
};

// Consecutive index pairs (evo filter_pairs_by_index, all_pairs = False). delta >= 1.
IdPairs pairsByIndex(std::size_t num_poses, std::size_t delta);
// Consecutive pairs by travelled path (evo filter_pairs_by_path, all_pairs = False). delta > 0 [m].
IdPairs pairsByPath(const Trajectory& trajectory, double delta);
// The same on the poses trajectory[indices[k]]; the pairs index k.
IdPairs pairsByPath(const Trajectory& trajectory, const std::vector<std::size_t>& indices, double delta);

// Errors of the given pairs (i, j) of matched poses: est_aligned[i], est_aligned[j] against
// ref[ref_index[i]], ref[ref_index[j]].
std::vector<double> relativeErrors(const Trajectory& ref, const std::vector<std::size_t>& ref_index,
                                   const Trajectory& est_aligned, const IdPairs& pairs, PoseRelation relation);

// Throws std::invalid_argument on a bad delta, no matches, degenerate alignment, or when the delta selects no
// pair ("try a smaller delta").
RpeResult computeRpe(const Trajectory& ref, const Trajectory& est, const RpeOptions& options = {});

}  // namespace drover::eval
