#include "geometry/trajectory_fill.hpp"

#include <algorithm>
#include <stdexcept>

#include "geometry/se3.hpp"

namespace drover::geometry {
namespace {

// Pose at t on the screw motion through a and b (alpha outside [0, 1] extrapolates).
Eigen::Isometry3d along(const StampedPose& a, const StampedPose& b, Time t) {
  const double alpha = static_cast<double>(t - a.t) / static_cast<double>(b.t - a.t);
  return interpolateGeodesic(a.T_world_body, b.T_world_body, alpha);
}

FilledPose fill(const Trajectory& tr, Time t) {
  const auto after = std::lower_bound(tr.begin(), tr.end(), t, [](const StampedPose& p, Time x) { return p.t < x; });
  if (after != tr.end() && after->t == t) return {*after, FillKind::kEstimated};
  if (after != tr.begin() && after != tr.end()) return {{t, along(*(after - 1), *after, t)}, FillKind::kInterpolated};
  if (tr.size() == 1) return {{t, tr.front().T_world_body}, FillKind::kExtrapolated};
  const bool before_first = after == tr.begin();
  const StampedPose& a = before_first ? tr[0] : tr[tr.size() - 2];
  const StampedPose& b = before_first ? tr[1] : tr.back();
  return {{t, along(a, b, t)}, FillKind::kExtrapolated};
}

}  // namespace

const char* toString(FillKind kind) {
  switch (kind) {
    case FillKind::kEstimated: return "estimated";
    case FillKind::kInterpolated: return "interpolated";
    case FillKind::kExtrapolated: return "extrapolated";
  }
  return "?";
}

std::vector<FilledPose> posesAtTimes(const Trajectory& trajectory, const std::vector<Time>& times) {
  if (trajectory.empty()) throw std::invalid_argument("posesAtTimes: empty trajectory");
  for (std::size_t i = 1; i < trajectory.size(); ++i)
    if (trajectory[i].t <= trajectory[i - 1].t)
      throw std::invalid_argument("posesAtTimes: trajectory times must increase");
  std::vector<FilledPose> out;
  out.reserve(times.size());
  for (Time t : times) out.push_back(fill(trajectory, t));
  return out;
}

}  // namespace drover::geometry
