#include "pipeline/visual_yaw_history.hpp"

#include <algorithm>
#include <cmath>

#include "geometry/so3.hpp"

namespace drover::pipeline {

VisualYawHistory::VisualYawHistory(const Eigen::Isometry3d& T_imu_lidar, double spacing_s, double max_gap_s)
    : q_imu_lidar_(T_imu_lidar.linear()), spacing_(fromSeconds(spacing_s)), max_gap_(fromSeconds(max_gap_s)) {}

void VisualYawHistory::add(const VisualState& state) {
  std::lock_guard<std::mutex> lock(mutex_);
  // A new reset ID is always kept: its first state must not be swallowed by the spacing.
  if (!entries_.empty() && entries_.back().reset_id == state.reset_id && state.t < entries_.back().t + spacing_)
    return;
  if (!entries_.empty() && state.t <= entries_.back().t) return;
  entries_.push_back({state.t, Eigen::Quaterniond(state.T_world_imu.linear()).normalized(), state.reset_id});
}

const VisualYawHistory::Entry* VisualYawHistory::nearest(Time t) const {
  const auto it = std::lower_bound(entries_.begin(), entries_.end(), t,
                                   [](const Entry& e, Time x) { return e.t < x; });
  const Entry* best = nullptr;
  if (it != entries_.end()) best = &*it;
  if (it != entries_.begin() && (best == nullptr || t - std::prev(it)->t < best->t - t)) best = &*std::prev(it);
  if (best == nullptr || std::abs(best->t - t) > max_gap_) return nullptr;
  return best;
}

std::optional<double> VisualYawHistory::yaw(Time t_candidate, Time t_query) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const Entry* c = nearest(t_candidate);
  const Entry* q = nearest(t_query);
  if (c == nullptr || q == nullptr || c->reset_id != q->reset_id) return std::nullopt;
  const Eigen::Matrix3d R_c_q =
      (q_imu_lidar_.conjugate() * c->q_world_imu.conjugate() * q->q_world_imu * q_imu_lidar_).toRotationMatrix();
  return geometry::yawOf(R_c_q);
}

VisualYawPrior VisualYawHistory::prior() const {
  return [this](Time t_candidate, Time t_query) { return yaw(t_candidate, t_query); };
}

std::size_t VisualYawHistory::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

}  // namespace drover::pipeline
