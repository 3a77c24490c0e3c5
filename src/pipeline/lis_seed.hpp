#pragma once
// What the VIS takes from the LIS (LVI-SAM's initialisation and lidar depth): the LIS's IMU-rate pose at a camera
// stamp and its full state there. Shared by the replay (apps/drover/run_vis.cpp, over LidarOdometry's whole
// IMU-rate trajectory) and the live system (pipeline::System, over a bounded buffer of the poses it published).
#include <Eigen/Geometry>
#include <algorithm>
#include <iterator>
#include <optional>

#include "imu/preintegration.hpp"
#include "types/trajectory.hpp"
#include "vio/sliding_window.hpp"

namespace drover::pipeline {

// A camera frame may arrive before the IMU sample after it: up to this long past the newest IMU-rate pose, that
// pose is used as it is.
constexpr Time kLisPoseMaxAhead = 20'000'000;  // [ns]
// The VIS's velocity seed is the IMU-rate pose difference over this interval (first order; the window's IMU
// factors refine it).
constexpr Time kLisVelocityBaseline = 40'000'000;  // [ns]

// T_world_imu of the IMU-rate odometry at t (time-ordered StampedPose container: Trajectory or a deque):
// interpolated between its samples (slerp and linear), or the newest sample up to kLisPoseMaxAhead past it.
template <class Poses>
std::optional<Eigen::Isometry3d> lisPoseAt(const Poses& imu_rate, Time t) {
  if (imu_rate.empty() || t < imu_rate.front().t) return std::nullopt;
  const auto it = std::lower_bound(imu_rate.begin(), imu_rate.end(), t,
                                   [](const StampedPose& p, Time x) { return p.t < x; });
  if (it == imu_rate.end()) {
    if (t - imu_rate.back().t > kLisPoseMaxAhead) return std::nullopt;
    return imu_rate.back().T_world_body;
  }
  if (it->t == t || it == imu_rate.begin()) return it->T_world_body;
  const StampedPose& a = *std::prev(it);
  const StampedPose& b = *it;
  const double s = static_cast<double>(t - a.t) / static_cast<double>(b.t - a.t);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(a.T_world_body.rotation())
                   .slerp(s, Eigen::Quaterniond(b.T_world_body.rotation()))
                   .toRotationMatrix();
  T.translation() = (1 - s) * a.T_world_body.translation() + s * b.T_world_body.translation();
  return T;
}

// The LIS's state at a camera stamp: its IMU-rate pose, the velocity from the poses kLisVelocityBaseline apart,
// and the biases of its newest fused sweep.
template <class Poses>
std::optional<vio::SeedState> lisSeedAt(const Poses& imu_rate, Time t, const imu::ImuBias& bias) {
  const std::optional<Eigen::Isometry3d> T = lisPoseAt(imu_rate, t);
  const std::optional<Eigen::Isometry3d> T_before = lisPoseAt(imu_rate, t - kLisVelocityBaseline);
  if (!T || !T_before) return std::nullopt;
  vio::SeedState s;
  s.T_world_imu = *T;
  s.v_world = (T->translation() - T_before->translation()) / toSeconds(kLisVelocityBaseline);
  s.bias = bias;
  return s;
}

// The LIS can seed the VIS once it fuses the IMU and has matched a few sweeps; it should be waited for while it
// still may (IMU enabled and initialised, or within its first start_sweeps sweeps).
constexpr std::size_t kLisSeedMinSweeps = 5;
constexpr std::size_t kLisStartSweeps = 20;

}  // namespace drover::pipeline
