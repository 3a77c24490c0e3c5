#include "backend/pose_factors.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "backend/jacobian_util.hpp"
#include "geometry/so3.hpp"

namespace drover::backend {

namespace {

void checkMeasurement(const char* who, const Eigen::Isometry3d& T, const Matrix6d& L) {
  if (!T.matrix().allFinite()) throw std::invalid_argument(std::string(who) + ": measured pose is not finite");
  if (!L.allFinite()) throw std::invalid_argument(std::string(who) + ": sqrt information is not finite");
}

Eigen::Quaterniond quaternionAt(const double* q) { return Eigen::Map<const Eigen::Quaterniond>(q).normalized(); }

}  // namespace

Matrix6d poseSqrtInformation(double sigma_position, double sigma_rotation) {
  if (!(sigma_position > 0) || !(sigma_rotation > 0) || !std::isfinite(sigma_position) ||
      !std::isfinite(sigma_rotation)) {
    throw std::invalid_argument("poseSqrtInformation: sigma_position = " + std::to_string(sigma_position) +
                                " m, sigma_rotation = " + std::to_string(sigma_rotation) + " rad must be > 0");
  }
  Vector6d d;
  d << Eigen::Vector3d::Constant(1.0 / sigma_position), Eigen::Vector3d::Constant(1.0 / sigma_rotation);
  return d.asDiagonal();
}

PosePriorFactor::PosePriorFactor(const Eigen::Isometry3d& T_world_imu_measured, const Matrix6d& sqrt_information)
    : p_measured_(T_world_imu_measured.translation()),
      R_measured_(Eigen::Quaterniond(T_world_imu_measured.linear()).normalized().toRotationMatrix()),
      sqrt_information_(sqrt_information) {
  checkMeasurement("PosePriorFactor", T_world_imu_measured, sqrt_information);
}

bool PosePriorFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> p(parameters[0]);
  const Eigen::Quaterniond q = quaternionAt(parameters[1]);
  const Eigen::Vector3d r_phi = geometry::logSO3(R_measured_.transpose() * q.toRotationMatrix());
  Vector6d r;
  r << p - p_measured_, r_phi;
  Eigen::Map<Vector6d>{residuals} = sqrt_information_ * r;
  if (jacobians == nullptr) return true;
  // d Log(R_m^T R Exp(dtheta)) / d dtheta = J_r^-1(r_phi).
  Eigen::Matrix<double, 6, 3> J_p = Eigen::Matrix<double, 6, 3>::Zero(), J_th = J_p;
  J_p.topRows<3>().setIdentity();
  J_th.bottomRows<3>() = geometry::rightJacobianInverseSO3(r_phi);
  setJacobian<6, 3>(jacobians[0], sqrt_information_ * J_p);
  setJacobian<6, 4>(jacobians[1], ambientFromTangent<6>(sqrt_information_ * J_th, q));
  return true;
}

RelativePoseFactor::RelativePoseFactor(const Eigen::Isometry3d& T_i_j_measured, const Matrix6d& sqrt_information)
    : t_measured_(T_i_j_measured.translation()),
      R_measured_(Eigen::Quaterniond(T_i_j_measured.linear()).normalized().toRotationMatrix()),
      sqrt_information_(sqrt_information) {
  checkMeasurement("RelativePoseFactor", T_i_j_measured, sqrt_information);
}

bool RelativePoseFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> p_i(parameters[0]), p_j(parameters[2]);
  const Eigen::Quaterniond q_i = quaternionAt(parameters[1]), q_j = quaternionAt(parameters[3]);
  const Eigen::Matrix3d R_i = q_i.toRotationMatrix(), R_j = q_j.toRotationMatrix();
  const Eigen::Vector3d t_i_j = R_i.transpose() * (p_j - p_i);  // [m], position of j in frame i
  const Eigen::Vector3d r_phi = geometry::logSO3(R_measured_.transpose() * R_i.transpose() * R_j);
  Vector6d r;
  r << t_i_j - t_measured_, r_phi;
  Eigen::Map<Vector6d>{residuals} = sqrt_information_ * r;
  if (jacobians == nullptr) return true;

  const Eigen::Matrix3d Jr_inv = geometry::rightJacobianInverseSO3(r_phi);
  Eigen::Matrix<double, 6, 3> J_p_i = Eigen::Matrix<double, 6, 3>::Zero(), J_th_i = J_p_i, J_p_j = J_p_i,
                              J_th_j = J_p_i;
  J_p_i.topRows<3>() = -R_i.transpose();
  J_p_j.topRows<3>() = R_i.transpose();
  // R_i -> R_i Exp(d): R_i^T -> Exp(-d) R_i^T, so d t_i_j = [t_i_j]_x d; the rotation error moves by
  // Exp(-R_j^T R_i d) on the right.
  J_th_i.topRows<3>() = geometry::hat(t_i_j);
  J_th_i.bottomRows<3>() = -Jr_inv * R_j.transpose() * R_i;
  J_th_j.bottomRows<3>() = Jr_inv;
  setJacobian<6, 3>(jacobians[0], sqrt_information_ * J_p_i);
  setJacobian<6, 4>(jacobians[1], ambientFromTangent<6>(sqrt_information_ * J_th_i, q_i));
  setJacobian<6, 3>(jacobians[2], sqrt_information_ * J_p_j);
  setJacobian<6, 4>(jacobians[3], ambientFromTangent<6>(sqrt_information_ * J_th_j, q_j));
  return true;
}

}  // namespace drover::backend
