#include "eval/association.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace drover::eval {

namespace {

void requireIncreasing(const Trajectory& trajectory, const char* name) {
  for (std::size_t i = 1; i < trajectory.size(); ++i)
    if (trajectory[i].t <= trajectory[i - 1].t)
      throw std::invalid_argument(std::string(name) + " trajectory: stamps not strictly increasing at pose " +
                                  std::to_string(i) + " (" + std::to_string(trajectory[i - 1].t) + " ns, then " +
                                  std::to_string(trajectory[i].t) + " ns)");
}

// Nearest stamp of `longer` (shifted by `shift`) for each stamp of `shorter`, as numpy.argmin's first minimum.
// Both are strictly increasing, so for one query the distance falls then rises along the longer trajectory
// (stop at the first minimum: a tie keeps the lower index), and the answer never moves back for a later query:
// one forward walk, O(n + m).
class NearestWalk {
 public:
  NearestWalk(const Trajectory& longer, Time shift) : longer_(longer), shift_(shift) {}
  std::size_t next(Time t, Time& dt_abs) {
    while (j_ + 1 < longer_.size() && distance(j_ + 1, t) < distance(j_, t)) ++j_;
    dt_abs = distance(j_, t);
    return j_;
  }

 private:
  // |t_j + shift - t| in 128 bits, saturated: stamps (up to 9e9 s) plus a user's offset (up to 4e9 s) may leave
  // int64 nanoseconds, and a wrapped difference would "match" poses that are centuries apart.
  Time distance(std::size_t j, Time t) const {
    const __int128 d = static_cast<__int128>(longer_[j].t) + shift_ - t;
    const __int128 a = d < 0 ? -d : d;
    return a > std::numeric_limits<Time>::max() ? std::numeric_limits<Time>::max() : static_cast<Time>(a);
  }
  const Trajectory& longer_;
  Time shift_;
  std::size_t j_ = 0;
};

}  // namespace

Association associate(const Trajectory& first, const Trajectory& second, const AssociationOptions& options) {
  if (options.max_diff < 0)
    throw std::invalid_argument("max time difference must be >= 0, got " + std::to_string(options.max_diff) + " ns");
  requireIncreasing(first, "first");
  requireIncreasing(second, "second");
  Association result;
  const bool second_longer = second.size() > first.size();
  const Trajectory& shorter = second_longer ? first : second;
  const Trajectory& longer = second_longer ? second : first;
  result.max_pairs = shorter.size();
  if (shorter.empty()) return result;
  // evo shifts the longer trajectory's stamps: by +offset when it is the second one, by -offset otherwise.
  const Time shift = second_longer ? options.offset : -options.offset;
  NearestWalk walk(longer, shift);
  std::vector<std::size_t>& short_idx = second_longer ? result.first : result.second;
  std::vector<std::size_t>& long_idx = second_longer ? result.second : result.first;
  short_idx.reserve(shorter.size());
  long_idx.reserve(shorter.size());
  for (std::size_t i = 0; i < shorter.size(); ++i) {
    Time dt = 0;
    const std::size_t j = walk.next(shorter[i].t, dt);
    if (dt <= options.max_diff) {
      short_idx.push_back(i);
      long_idx.push_back(j);
    }
  }
  return result;
}

Trajectory selectPoses(const Trajectory& trajectory, const std::vector<std::size_t>& indices) {
  Trajectory out;
  out.reserve(indices.size());
  for (const std::size_t i : indices) {
    if (i >= trajectory.size())
      throw std::invalid_argument("pose index " + std::to_string(i) + " out of range (" +
                                  std::to_string(trajectory.size()) + " poses)");
    out.push_back(trajectory[i]);
  }
  return out;
}

}  // namespace drover::eval
