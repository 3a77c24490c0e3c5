#pragma once
// Pose factors on the backend's parameter blocks p_world [m] (3) and q_world_imu (4, RightQuaternionManifold).
// Both use the decoupled SE(3) error [translation (3); rotation (3)] -- the translation error in the frame named
// below, the rotation error Log(R_measured^T R) on the right -- whitened by a 6x6 square-root information L
// (L^T L = Sigma^-1, Sigma the covariance of [dp; dphi], [m], [rad]). Backend-internal header.
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "backend/imu_factors.hpp"

namespace drover::backend {

// Sqrt information diag(1/sigma_position I3, 1/sigma_rotation I3); sigmas [m], [rad] must be > 0.
Matrix6d poseSqrtInformation(double sigma_position, double sigma_rotation);

// Absolute pose measurement (lidar odometry, GPS-like prior): r = L [p - p_m; Log(R_m^T R)], p in the world
// frame. Blocks: p, q.
class PosePriorFactor final : public ceres::SizedCostFunction<6, 3, 4> {
 public:
  // Throws std::invalid_argument when the measurement or L is not finite.
  PosePriorFactor(const Eigen::Isometry3d& T_world_imu_measured, const Matrix6d& sqrt_information);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Eigen::Vector3d p_measured_;
  Eigen::Matrix3d R_measured_;
  Matrix6d sqrt_information_;
};

// Relative pose T_i_j = T_world_i^-1 T_world_j (odometry, loop closure):
//   r = L [R_i^T (p_j - p_i) - t_m; Log(R_m^T R_i^T R_j)], the translation error in frame i.
// Blocks: p_i, q_i, p_j, q_j.
class RelativePoseFactor final : public ceres::SizedCostFunction<6, 3, 4, 3, 4> {
 public:
  // Throws std::invalid_argument when the measurement or L is not finite.
  RelativePoseFactor(const Eigen::Isometry3d& T_i_j_measured, const Matrix6d& sqrt_information);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Eigen::Vector3d t_measured_;
  Eigen::Matrix3d R_measured_;
  Matrix6d sqrt_information_;
};

}  // namespace drover::backend
