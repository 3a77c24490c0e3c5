#include "pipeline/motion_models.hpp"

#include <algorithm>
#include <cmath>

#include "geometry/se3.hpp"

namespace drover::pipeline {

Eigen::Isometry3d constantVelocityGuess(const Eigen::Isometry3d& T_world_last, const Eigen::Isometry3d& T_prev_last,
                                        double dt_prev, double dt) {
  if (!(dt_prev > 0) || !(dt > 0)) return T_world_last;
  return T_world_last * geometry::expSE3(geometry::logSE3(T_prev_last) * (dt / dt_prev));
}

std::optional<lidar::SweepMotion> imuMotion(const imu::ImuPropagator& propagator,
                                            const Eigen::Isometry3d& T_imu_lidar, Time t0, Time t_end) {
  const std::optional<imu::NavState> start = propagator.stateAt(t0);
  if (!start || propagator.latestTime() < t_end) return std::nullopt;
  const Eigen::Isometry3d T_lidar0_world = (start->T_world_imu * T_imu_lidar).inverse();
  const Time t_last = propagator.latestTime();
  return [&propagator, T_lidar0_world, T_imu_lidar, t0, t_last](double tau) {
    const Time t = std::clamp(t0 + fromSeconds(std::max(0.0, tau)), t0, t_last);
    const std::optional<imu::NavState> s = propagator.stateAt(t);
    // Covered by construction; identity keeps a point where it was measured if the buffer moved on.
    return s ? Eigen::Isometry3d(T_lidar0_world * s->T_world_imu * T_imu_lidar) : Eigen::Isometry3d::Identity();
  };
}

}  // namespace drover::pipeline
