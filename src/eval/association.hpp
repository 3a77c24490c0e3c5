#pragma once
// Time association of two trajectories, with the semantics of evo's sync.associate_trajectories
// (nearest-time matching; github.com/MichaelGrupp/evo, evo/core/sync.py):
//  - the SHORTER trajectory is iterated (the first one when both have the same length, evo's `snd_longer` is
//    false then, so the second is iterated); for each of its stamps the nearest stamp of the other trajectory is
//    taken (first index on ties, as numpy.argmin), after shifting the second trajectory's stamps by `offset`;
//  - a pair is kept when |dt| <= max_diff. A pose of the longer trajectory may be matched more than once.
// Stamps must be strictly increasing (what the readers guarantee); the nearest lookups are then one forward walk.
#include <cstddef>
#include <vector>

#include "types/trajectory.hpp"

namespace drover::eval {

struct AssociationOptions {
  Time max_diff = 10'000'000;  // [ns] largest accepted |t_first - (t_second + offset)|; evo's default 0.01 s
  Time offset = 0;             // [ns] added to the second trajectory's stamps (evo's offset_2)
};

struct Association {
  // Matched pairs in the iteration order of the shorter trajectory: first[k] (index into the first trajectory)
  // goes with second[k] (index into the second).
  std::vector<std::size_t> first;
  std::vector<std::size_t> second;
  std::size_t max_pairs = 0;  // the shorter trajectory's length: evo's "of max. N possible matching timestamps"
  std::size_t size() const { return first.size(); }
};

// Throws std::invalid_argument when max_diff < 0 or a trajectory's stamps are not strictly increasing.
// An empty result is not an error here; callers decide how many pairs they need.
Association associate(const Trajectory& first, const Trajectory& second, const AssociationOptions& options = {});

// The poses of `trajectory` at `indices`, in that order.
Trajectory selectPoses(const Trajectory& trajectory, const std::vector<std::size_t>& indices);

}  // namespace drover::eval
