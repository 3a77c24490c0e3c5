#include "backend/visual_factors.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "backend/jacobian_util.hpp"
#include "geometry/so3.hpp"

namespace drover::backend {

using geometry::hat;

namespace {

constexpr double kMinDepth = 1e-9;  // [m] P_cj.z below this: behind (or on) camera j's image plane

// The chain anchor camera i -> IMU i -> world -> IMU j -> camera j, computed once and shared by the residual and
// every Jacobian.
struct Chain {
  Eigen::Quaterniond q_i, q_j, q_ic;
  Eigen::Matrix3d R_wi, R_wj, R_ic;
  Eigen::Vector3d n_i;   // anchor ray at state time i (z = 1)
  Eigen::Vector3d P_ci;  // [m] in camera i
  Eigen::Vector3d P_bi;  // [m] in IMU i
  Eigen::Vector3d P_bj;  // [m] in IMU j
  Eigen::Vector3d P_cj;  // [m] in camera j
  double lambda;         // [1/m]
  double td;             // [s]
};

Chain transformChain(double const* const* parameters, const Eigen::Vector2d& obs_i, const Eigen::Vector2d& vel_i,
                     double td_i) {
  Chain c;
  const Eigen::Map<const Eigen::Vector3d> p_wi(parameters[0]), p_wj(parameters[2]), p_ic(parameters[4]);
  c.q_i = Eigen::Map<const Eigen::Quaterniond>(parameters[1]).normalized();
  c.q_j = Eigen::Map<const Eigen::Quaterniond>(parameters[3]).normalized();
  c.q_ic = Eigen::Map<const Eigen::Quaterniond>(parameters[5]).normalized();
  c.lambda = parameters[6][0];
  c.td = parameters[7][0];
  c.R_wi = c.q_i.toRotationMatrix();
  c.R_wj = c.q_j.toRotationMatrix();
  c.R_ic = c.q_ic.toRotationMatrix();
  // The observation moved from its capture time to the state time at the feature's image velocity.
  c.n_i << obs_i - (c.td - td_i) * vel_i, 1.0;
  c.P_ci = c.n_i / c.lambda;
  c.P_bi = c.R_ic * c.P_ci + p_ic;
  c.P_bj = c.R_wj.transpose() * (c.R_wi * c.P_bi + p_wi - p_wj);
  c.P_cj = c.R_ic.transpose() * (c.P_bj - p_ic);
  return c;
}

}  // namespace

ReprojectionFactor::ReprojectionFactor(const Eigen::Vector2d& obs_i, const Eigen::Vector2d& obs_j,
                                       const Eigen::Vector2d& velocity_i, const Eigen::Vector2d& velocity_j,
                                       double td_i, double td_j, double sqrt_information)
    : obs_i_(obs_i),
      obs_j_(obs_j),
      velocity_i_(velocity_i),
      velocity_j_(velocity_j),
      td_i_(td_i),
      td_j_(td_j),
      sqrt_information_(sqrt_information) {
  if (!obs_i.allFinite() || !obs_j.allFinite() || !velocity_i.allFinite() || !velocity_j.allFinite() ||
      !std::isfinite(td_i) || !std::isfinite(td_j)) {
    throw std::invalid_argument("ReprojectionFactor: observations, velocities and td_i, td_j must be finite");
  }
  if (!(std::isfinite(sqrt_information) && sqrt_information > 0)) {
    throw std::invalid_argument("ReprojectionFactor: sqrt_information = " + std::to_string(sqrt_information) +
                                " must be finite and > 0");
  }
}

double ReprojectionFactor::cheirality(double const* const* parameters) const {
  return transformChain(parameters, obs_i_, velocity_i_, td_i_).P_cj.z();
}

bool ReprojectionFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Chain c = transformChain(parameters, obs_i_, velocity_i_, td_i_);
  // Only a singular projection fails (Ceres then rejects the whole step). A point behind a camera, or a negative
  // inverse depth, gives a large finite residual that the robust loss bounds, as in VINS-Mono: with hundreds of
  // features in a forward-moving window some far, low-parallax feature flips sign in nearly every trial step, and
  // failing on it would freeze the solve. The estimator drops such features after the solve. !(x > t) rejects NaN.
  if (!(std::abs(c.lambda) > 0) || !(std::abs(c.P_cj.z()) > kMinDepth) || !c.P_cj.allFinite() || !std::isfinite(c.td))
    return false;

  const double s = sqrt_information_;
  const double inv_z = 1.0 / c.P_cj.z();
  const Eigen::Vector2d n_j = obs_j_ - (c.td - td_j_) * velocity_j_;
  Eigen::Map<Eigen::Vector2d> r(residuals);
  r = s * (c.P_cj.head<2>() * inv_z - n_j);
  if (!r.allFinite()) return false;
  if (jacobians == nullptr) return true;

  // d r / d P_cj: the weighted pinhole projection Jacobian.
  Eigen::Matrix<double, 2, 3> J_proj;
  J_proj << s * inv_z, 0, -s * c.P_cj.x() * inv_z * inv_z,  //
      0, s * inv_z, -s * c.P_cj.y() * inv_z * inv_z;
  // Shared products: J_A = J_proj R_ic^T R_wj^T (d r / d P_w), J_B = J_A R_wi (d r / d P_bi),
  // J_C = J_proj R_ic^T (d r / d P_bj), J_D = J_B R_ic (d r / d P_ci).
  const Eigen::Matrix<double, 2, 3> J_C = J_proj * c.R_ic.transpose();
  const Eigen::Matrix<double, 2, 3> J_A = J_C * c.R_wj.transpose();
  const Eigen::Matrix<double, 2, 3> J_B = J_A * c.R_wi;
  const Eigen::Matrix<double, 2, 3> J_D = J_B * c.R_ic;

  // Tangent Jacobians, rotations perturbed on the right: R Exp(dtheta) x = R x - R hat(x) dtheta and
  // (R Exp(dtheta))^T x = R^T x + hat(R^T x) dtheta. setJacobian skips null blocks; the Eigen expressions passed
  // to it are lazy, so only the rotation blocks (evaluated as arguments) need their own null check.
  setJacobian<2, 3>(jacobians[0], J_A);
  if (jacobians[1] != nullptr) {
    setJacobian<2, 4>(jacobians[1], ambientFromTangent<2>(-J_B * hat(c.P_bi), c.q_i));
  }
  setJacobian<2, 3>(jacobians[2], -J_A);
  if (jacobians[3] != nullptr) {
    setJacobian<2, 4>(jacobians[3], ambientFromTangent<2>(J_C * hat(c.P_bj), c.q_j));
  }
  // p_ic enters at IMU i (+R_wj^T R_wi) and is removed at IMU j (-I).
  setJacobian<2, 3>(jacobians[4], J_B - J_C);
  // R_ic enters twice: rotating P_ci into IMU i, and (transposed) rotating IMU j into camera j.
  if (jacobians[5] != nullptr) {
    setJacobian<2, 4>(jacobians[5], ambientFromTangent<2>(J_proj * hat(c.P_cj) - J_D * hat(c.P_ci), c.q_ic));
  }
  // d P_ci / d lambda = -n_i / lambda^2 = -P_ci / lambda.
  setJacobian<2, 1>(jacobians[6], -J_D * c.P_ci / c.lambda);
  // d n_i / d td = [-v_i; 0], d n_j / d td = [-v_j; 0] (r subtracts n_j).
  setJacobian<2, 1>(jacobians[7], -J_D.leftCols<2>() * velocity_i_ / c.lambda + s * velocity_j_);
  return true;
}

InverseDepthFactor::InverseDepthFactor(double depth, double sigma_depth) {
  if (!(std::isfinite(depth) && depth > 0) || !(std::isfinite(sigma_depth) && sigma_depth > 0)) {
    throw std::invalid_argument("InverseDepthFactor: depth = " + std::to_string(depth) + " m, sigma_depth = " +
                                std::to_string(sigma_depth) + " m must be finite and > 0");
  }
  inverse_depth_ = 1.0 / depth;
  // sigma(1/d) = sigma_d / d^2 to first order (d(1/d)/dd = -1/d^2).
  weight_ = depth * depth / sigma_depth;
}

bool InverseDepthFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  residuals[0] = weight_ * (parameters[0][0] - inverse_depth_);
  if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = weight_;
  return std::isfinite(residuals[0]);
}

}  // namespace drover::backend
