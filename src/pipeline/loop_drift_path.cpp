#include "pipeline/loop_drift_path.hpp"

#include <limits>
#include <queue>
#include <stdexcept>

namespace drover::pipeline {

DriftPath cheapestDriftPath(const std::vector<DriftStep>& steps,
                            const std::vector<std::pair<std::size_t, std::size_t>>& loops, std::size_t from,
                            std::size_t to) {
  const std::size_t n = steps.size();
  if (from >= n || to >= n) throw std::invalid_argument("cheapestDriftPath: keyframe index out of range");
  std::vector<std::vector<std::size_t>> shortcuts(n);
  for (const auto& [a, b] : loops) {
    if (a >= n || b >= n) continue;  // a loop to keyframes the steps do not cover yet
    shortcuts[a].push_back(b);
    shortcuts[b].push_back(a);
  }
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<DriftPath> best(n, DriftPath{kInf, kInf});
  using Entry = std::pair<double, std::size_t>;  // (cost so far, keyframe)
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  best[from] = {0, 0};
  open.emplace(0.0, from);
  const auto relax = [&](std::size_t k, double cost, double length) {
    if (cost >= best[k].cost) return;
    best[k] = {cost, length};
    open.emplace(cost, k);
  };
  while (!open.empty()) {
    const auto [cost, i] = open.top();
    open.pop();
    if (cost > best[i].cost) continue;  // a stale entry
    if (i == to) return best[i];
    const DriftPath here = best[i];
    if (i > 0) relax(i - 1, here.cost + steps[i].cost, here.length + steps[i].length);
    if (i + 1 < n) relax(i + 1, here.cost + steps[i + 1].cost, here.length + steps[i + 1].length);
    for (std::size_t k : shortcuts[i]) relax(k, here.cost, here.length);
  }
  return best[to];
}

}  // namespace drover::pipeline
