#pragma once
// Ceres factors of the IMU: the preintegrated-measurement factor between two navigation states (Forster et al.,
// TRO 2017, Eq. 45 with the Jacobians of Appendix C / Sec. VI-B) and the bias random walk (Eq. 47-48).
// Parameter blocks (shared by every backend factor): p_world [m] (3), q_world_imu (4, Eigen (x, y, z, w) order,
// RightQuaternionManifold), v_world [m/s] (3), bias = [b_g (rad/s); b_a (m/s^2)] (6).
// Backend-internal header (included by backend .cpp files and tests only).
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "imu/preintegration.hpp"

namespace drover::backend {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// Upper-triangular L with L^T L = covariance^-1 (the whitening matrix). Throws std::invalid_argument when the
// covariance is not finite, symmetric positive definite.
template <int N>
Eigen::Matrix<double, N, N> sqrtInformationFromCovariance(const Eigen::Matrix<double, N, N>& covariance);

// Residual L * [r_phi; r_v; r_p] (9) of Preintegrator::residual(state_i, state_j, bias_i), L the whitening of the
// preintegration covariance. Blocks: p_i, q_i, v_i, bias_i, p_j, q_j, v_j.
class ImuPreintegrationFactor final : public ceres::SizedCostFunction<9, 3, 4, 3, 6, 3, 4, 3> {
 public:
  // Copies the preintegration. Throws std::invalid_argument when pim.deltaTime() <= 0 or its covariance is not
  // positive definite (e.g. an all-zero noise model).
  explicit ImuPreintegrationFactor(const imu::Preintegrator& pim);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  const imu::Preintegrator& preintegration() const { return pim_; }
  const imu::Matrix9d& sqrtInformation() const { return sqrt_information_; }

 private:
  imu::Preintegrator pim_;
  imu::Matrix9d sqrt_information_;
};

// Residual W (b_j - b_i) (6), W = diag(1 / (sigma_g sqrt(dt)) I3, 1 / (sigma_a sqrt(dt)) I3): the discrete
// random walk of the biases over dt. Blocks: bias_i, bias_j.
class BiasRandomWalkFactor final : public ceres::SizedCostFunction<6, 6, 6> {
 public:
  // gyro_random_walk [rad/s^2/sqrt(Hz)], acc_random_walk [m/s^3/sqrt(Hz)], dt [s]; all must be > 0 and finite
  // (std::invalid_argument otherwise).
  BiasRandomWalkFactor(double gyro_random_walk, double acc_random_walk, double dt);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Vector6d weights_;
};

// A prior on one frame's biases [b_g; b_a] around a measured value (another estimator's biases: the LIS's, in the
// VIS window): r = (b - b_measured) / sigma per axis. gyro_sigma [rad/s], acc_sigma [m/s^2]; both must be > 0 and
// finite (std::invalid_argument otherwise).
class BiasPriorFactor final : public ceres::SizedCostFunction<6, 6> {
 public:
  BiasPriorFactor(const Vector6d& measured, double gyro_sigma, double acc_sigma);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Vector6d measured_;
  Vector6d weights_;
};

}  // namespace drover::backend
