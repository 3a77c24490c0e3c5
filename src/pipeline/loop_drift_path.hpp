#pragma once
// How far the odometry can have drifted between two keyframes, measured along the cheapest keyframe path when the
// accepted loops are shortcuts. The keyframe chain between a query and a candidate two laps older is two laps of
// path, but the graph already holds the two places together through the loops of the laps in between: what can
// still be wrong between them is the odometry since the places were last tied, not two laps of it. (A loop budget
// by keyframe index let a third-lap loop turn a correct estimate 31 deg towards a candidate whose own pose was off,
// on a budget of 33 deg over 750 m of path, bench/RESULTS.md.)
#include <cstddef>
#include <utility>
#include <vector>

namespace drover::pipeline {

// One odometry step: keyframe i - 1 -> i, and what the budget charges for it.
struct DriftStep {
  double length = 0;  // [m] between the two keyframes' current positions
  double cost = 0;    // [m or rad] what the budget adds for this step (ratio * length + degenerate share)
};

struct DriftPath {
  double cost = 0;    // summed step costs along the cheapest path
  double length = 0;  // [m] path length along it (steps only; loops add none)
};

// The cheapest path from keyframe `from` to keyframe `to` over the odometry steps (steps[i] joins i - 1 and i;
// steps[0] is unused) and the accepted loops (free, both directions). Dijkstra, O((n + loops) log n).
DriftPath cheapestDriftPath(const std::vector<DriftStep>& steps,
                            const std::vector<std::pair<std::size_t, std::size_t>>& loops, std::size_t from,
                            std::size_t to);

}  // namespace drover::pipeline
