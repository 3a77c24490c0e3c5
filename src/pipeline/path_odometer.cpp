#include "pipeline/path_odometer.hpp"

#include <algorithm>
#include <iterator>

namespace drover::pipeline {

void PathOdometer::add(Time t, const Eigen::Vector3d& p_world) {
  if (!s_.empty() && t <= s_.back().first) return;
  if (!p_world.allFinite()) return;
  const double s = s_.empty() ? 0.0 : s_.back().second + (last_ ? (p_world - *last_).norm() : 0.0);
  s_.emplace_back(t, s);
  last_ = p_world;
  while (s_.front().first < t - kKept) s_.pop_front();
}

void PathOdometer::moveWorld(const Eigen::Isometry3d& T_new_old) {
  if (last_) last_ = T_new_old * *last_;
}

double PathOdometer::at(Time t) const {
  if (s_.empty()) return 0.0;
  if (t <= s_.front().first) return s_.front().second;
  if (t >= s_.back().first) return s_.back().second;
  const auto hi = std::lower_bound(s_.begin(), s_.end(), t,
                                   [](const std::pair<Time, double>& e, Time x) { return e.first < x; });
  const auto lo = std::prev(hi);
  const double f = static_cast<double>(t - lo->first) / static_cast<double>(hi->first - lo->first);
  return lo->second + f * (hi->second - lo->second);
}

double PathOdometer::between(Time t0, Time t1) const { return t1 <= t0 ? 0.0 : at(t1) - at(t0); }

}  // namespace drover::pipeline
