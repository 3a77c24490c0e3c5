#include "backend/imu_factors.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "backend/jacobian_util.hpp"
#include "geometry/so3.hpp"

namespace drover::backend {

using geometry::hat;

template <int N>
Eigen::Matrix<double, N, N> sqrtInformationFromCovariance(const Eigen::Matrix<double, N, N>& covariance) {
  using Matrix = Eigen::Matrix<double, N, N>;
  if (!covariance.allFinite()) throw std::invalid_argument("sqrtInformationFromCovariance: covariance not finite");
  const Matrix symmetric = 0.5 * (covariance + covariance.transpose());
  const Eigen::LLT<Matrix> llt_cov(symmetric);
  if (llt_cov.info() != Eigen::Success) {
    throw std::invalid_argument("sqrtInformationFromCovariance: covariance is not positive definite (diagonal " +
                                std::to_string(symmetric.diagonal().minCoeff()) + " min)");
  }
  const Matrix information = llt_cov.solve(Matrix::Identity());
  const Eigen::LLT<Matrix> llt_info(0.5 * (information + information.transpose()));
  if (llt_info.info() != Eigen::Success) {
    throw std::invalid_argument("sqrtInformationFromCovariance: information is not positive definite");
  }
  return llt_info.matrixU();  // U^T U = information
}

template Eigen::Matrix<double, 3, 3> sqrtInformationFromCovariance<3>(const Eigen::Matrix<double, 3, 3>&);
template Eigen::Matrix<double, 6, 6> sqrtInformationFromCovariance<6>(const Eigen::Matrix<double, 6, 6>&);
template Eigen::Matrix<double, 9, 9> sqrtInformationFromCovariance<9>(const Eigen::Matrix<double, 9, 9>&);
template Eigen::Matrix<double, 15, 15> sqrtInformationFromCovariance<15>(const Eigen::Matrix<double, 15, 15>&);

namespace {

imu::Matrix9d checkedSqrtInformation(const imu::Preintegrator& pim) {
  if (!(pim.deltaTime() > 0)) {
    throw std::invalid_argument("ImuPreintegrationFactor: deltaTime = " + std::to_string(pim.deltaTime()) +
                                " s must be > 0");
  }
  return sqrtInformationFromCovariance<9>(pim.covariance());
}

}  // namespace

ImuPreintegrationFactor::ImuPreintegrationFactor(const imu::Preintegrator& pim)
    : pim_(pim), sqrt_information_(checkedSqrtInformation(pim)) {}

bool ImuPreintegrationFactor::Evaluate(double const* const* parameters, double* residuals,
                                       double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> p_i(parameters[0]), v_i(parameters[2]);
  const Eigen::Quaterniond q_i = Eigen::Map<const Eigen::Quaterniond>(parameters[1]).normalized();
  const Eigen::Map<const Vector6d> b_i(parameters[3]);
  const Eigen::Map<const Eigen::Vector3d> p_j(parameters[4]), v_j(parameters[6]);
  const Eigen::Quaterniond q_j = Eigen::Map<const Eigen::Quaterniond>(parameters[5]).normalized();

  const double dt = pim_.deltaTime();
  const Eigen::Vector3d g = pim_.gravityWorld();
  const Eigen::Matrix3d R_i = q_i.toRotationMatrix(), R_j = q_j.toRotationMatrix();
  const Eigen::Matrix3d Rt_i = R_i.transpose();
  imu::ImuBias bias;
  bias.gyro = b_i.head<3>();
  bias.acc = b_i.tail<3>();
  const Eigen::Vector3d dbg = bias.gyro - pim_.biasHat().gyro;

  // Forster Eq. 45 (the same expressions as Preintegrator::residual, kept here for their Jacobians).
  const Eigen::Vector3d dv_world = v_j - v_i - g * dt;                                  // [m/s]
  const Eigen::Vector3d dp_world = p_j - p_i - v_i * dt - 0.5 * g * dt * dt;            // [m]
  const Eigen::Vector3d r_phi = geometry::logSO3(pim_.correctedDeltaR(bias).transpose() * Rt_i * R_j);
  imu::Vector9d r;
  r << r_phi, Rt_i * dv_world - pim_.correctedDeltaV(bias), Rt_i * dp_world - pim_.correctedDeltaP(bias);
  Eigen::Map<imu::Vector9d>{residuals} = sqrt_information_ * r;
  if (jacobians == nullptr) return true;

  const Eigen::Matrix3d Jr_inv = geometry::rightJacobianInverseSO3(r_phi);
  // Tangent Jacobians, rows [phi, v, p]; position and velocity perturbed additively in the world frame,
  // rotation on the right (R -> R Exp(dtheta)).
  Eigen::Matrix<double, 9, 3> J_p_i = Eigen::Matrix<double, 9, 3>::Zero(), J_th_i = J_p_i, J_v_i = J_p_i,
                              J_p_j = J_p_i, J_th_j = J_p_i, J_v_j = J_p_i;
  Eigen::Matrix<double, 9, 6> J_b_i = Eigen::Matrix<double, 9, 6>::Zero();
  J_th_i.block<3, 3>(0, 0) = -Jr_inv * R_j.transpose() * R_i;
  J_th_i.block<3, 3>(3, 0) = hat(Rt_i * dv_world);
  J_th_i.block<3, 3>(6, 0) = hat(Rt_i * dp_world);
  J_v_i.block<3, 3>(3, 0) = -Rt_i;
  J_v_i.block<3, 3>(6, 0) = -Rt_i * dt;
  J_p_i.block<3, 3>(6, 0) = -Rt_i;
  J_th_j.block<3, 3>(0, 0) = Jr_inv;
  J_v_j.block<3, 3>(3, 0) = Rt_i;
  J_p_j.block<3, 3>(6, 0) = Rt_i;
  // Bias: d r_phi / d b_g = -J_r^-1(r_phi) Exp(r_phi)^T J_r(dR/dbg dbg) dR/dbg (Forster Eq. 45 ff.).
  J_b_i.block<3, 3>(0, 0) = -Jr_inv * geometry::expSO3(r_phi).transpose() *
                            geometry::rightJacobianSO3(pim_.dR_dbg() * dbg) * pim_.dR_dbg();
  J_b_i.block<3, 3>(3, 0) = -pim_.dV_dbg();
  J_b_i.block<3, 3>(3, 3) = -pim_.dV_dba();
  J_b_i.block<3, 3>(6, 0) = -pim_.dP_dbg();
  J_b_i.block<3, 3>(6, 3) = -pim_.dP_dba();

  const auto& L = sqrt_information_;
  setJacobian<9, 3>(jacobians[0], L * J_p_i);
  setJacobian<9, 4>(jacobians[1], ambientFromTangent<9>(L * J_th_i, q_i));
  setJacobian<9, 3>(jacobians[2], L * J_v_i);
  setJacobian<9, 6>(jacobians[3], L * J_b_i);
  setJacobian<9, 3>(jacobians[4], L * J_p_j);
  setJacobian<9, 4>(jacobians[5], ambientFromTangent<9>(L * J_th_j, q_j));
  setJacobian<9, 3>(jacobians[6], L * J_v_j);
  return true;
}

BiasRandomWalkFactor::BiasRandomWalkFactor(double gyro_random_walk, double acc_random_walk, double dt) {
  const auto positive = [](double x) { return std::isfinite(x) && x > 0; };
  if (!positive(gyro_random_walk) || !positive(acc_random_walk) || !positive(dt)) {
    throw std::invalid_argument("BiasRandomWalkFactor: gyro_random_walk = " + std::to_string(gyro_random_walk) +
                                ", acc_random_walk = " + std::to_string(acc_random_walk) + ", dt = " +
                                std::to_string(dt) + " must all be finite and > 0");
  }
  // Discrete random walk over dt: b_j - b_i ~ N(0, sigma^2 dt) (Forster Eq. 48).
  weights_ << Eigen::Vector3d::Constant(1.0 / (gyro_random_walk * std::sqrt(dt))),
      Eigen::Vector3d::Constant(1.0 / (acc_random_walk * std::sqrt(dt)));
}

bool BiasRandomWalkFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Vector6d> b_i(parameters[0]), b_j(parameters[1]);
  Eigen::Map<Vector6d>{residuals} = weights_.cwiseProduct(b_j - b_i);
  if (jacobians == nullptr) return true;
  const Matrix6d W = weights_.asDiagonal();
  setJacobian<6, 6>(jacobians[0], -W);
  setJacobian<6, 6>(jacobians[1], W);
  return true;
}

BiasPriorFactor::BiasPriorFactor(const Vector6d& measured, double gyro_sigma, double acc_sigma)
    : measured_(measured) {
  const auto positive = [](double x) { return std::isfinite(x) && x > 0; };
  if (!positive(gyro_sigma) || !positive(acc_sigma) || !measured.allFinite()) {
    throw std::invalid_argument("BiasPriorFactor: gyro_sigma = " + std::to_string(gyro_sigma) + ", acc_sigma = " +
                                std::to_string(acc_sigma) + " must be finite and > 0, and the measured bias finite");
  }
  weights_ << Eigen::Vector3d::Constant(1.0 / gyro_sigma), Eigen::Vector3d::Constant(1.0 / acc_sigma);
}

bool BiasPriorFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Vector6d> b(parameters[0]);
  Eigen::Map<Vector6d>{residuals} = weights_.cwiseProduct(b - measured_);
  if (jacobians == nullptr) return true;
  setJacobian<6, 6>(jacobians[0], Matrix6d(weights_.asDiagonal()));
  return true;
}

}  // namespace drover::backend
