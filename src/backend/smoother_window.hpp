#pragma once
// The fixed-lag smoother's window: parameter blocks and measurements of each state, the factor graph built from
// them, and the marginalisation of the oldest state. Backend-internal (FixedLagSmoother's implementation).
#include <ceres/manifold.h>
#include <ceres/problem.h>

#include <array>
#include <deque>
#include <optional>
#include <string>

#include "backend/marginalization.hpp"
#include "backend/pose_factors.hpp"
#include "imu/preintegration.hpp"

namespace drover::backend {

struct WindowNode {
  Time t = 0;  // [ns]
  // Parameter blocks (Ceres optimises these in place): p_world [m], q_world_imu (x, y, z, w), v_world [m/s],
  // bias [b_g rad/s; b_a m/s^2].
  std::array<double, 3> p{};
  std::array<double, 4> q{0, 0, 0, 1};
  std::array<double, 3> v{};
  std::array<double, 6> b{};
  std::optional<imu::Preintegrator> pim;          // IMU from the previous node to this one
  std::optional<Eigen::Isometry3d> pose_measured;  // lidar odometry T_world_imu
  Matrix6d pose_sqrt_information = Matrix6d::Identity();
  std::optional<Eigen::Isometry3d> relative_measured;  // T_prev_this from visual odometry (RelativePoseFactor)
  Matrix6d relative_sqrt_information = Matrix6d::Identity();

  std::array<double*, 4> blocks() { return {p.data(), q.data(), v.data(), b.data()}; }
  void set(const imu::NavState& state, const imu::ImuBias& bias);
  imu::NavState navState() const;
  imu::ImuBias imuBias() const;
  StatePoint statePoint() const;
};

struct LinearPrior {
  StatePoint linearization;
  Matrix15d sqrt_information = Matrix15d::Zero();
  Vector15d offset = Vector15d::Zero();
};

struct SmootherWindow {
  std::deque<WindowNode> nodes;
  LinearPrior prior;                   // on nodes.front()
  double gyro_random_walk = 0;         // [rad/s^2/sqrt(Hz)]
  double acc_random_walk = 0;          // [m/s^3/sqrt(Hz)]

  // Adds every block (quaternions on `manifold`, not owned by the problem) and factor of the window.
  void buildProblem(ceres::Problem& problem, ceres::Manifold* manifold);
  // Schur-complements nodes[0] into a prior on nodes[1] and drops it; on failure leaves the window unchanged
  // and returns the reason.
  std::string marginalizeFront();
};

}  // namespace drover::backend
