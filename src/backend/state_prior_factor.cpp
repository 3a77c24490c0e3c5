#include "backend/state_prior_factor.hpp"

#include <stdexcept>

#include "backend/jacobian_util.hpp"
#include "geometry/so3.hpp"

namespace drover::backend {

NavStatePriorFactor::NavStatePriorFactor(const StatePoint& linearization, const Matrix15d& sqrt_information,
                                         const Vector15d& offset)
    : lin_(linearization), sqrt_information_(sqrt_information), offset_(offset) {
  if (!lin_.p_world.allFinite() || !lin_.q_world_imu.coeffs().allFinite() || !lin_.v_world.allFinite() ||
      !lin_.bias.allFinite() || !sqrt_information.allFinite() || !offset.allFinite()) {
    throw std::invalid_argument("NavStatePriorFactor: linearisation point, sqrt information or offset not finite");
  }
  lin_.q_world_imu.normalize();
}

bool NavStatePriorFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> p(parameters[0]), v(parameters[2]);
  const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(parameters[1]).normalized();
  const Eigen::Map<const Vector6d> b(parameters[3]);
  const Eigen::Vector3d dtheta = geometry::logQuat(lin_.q_world_imu.conjugate() * q);
  Vector15d dx;
  dx << p - lin_.p_world, dtheta, v - lin_.v_world, b - lin_.bias;
  Eigen::Map<Vector15d>{residuals} = offset_ + sqrt_information_ * dx;
  if (jacobians == nullptr) return true;
  // d dx / d(tangent) is the identity except d Log(R_lin^T R Exp(d)) / d d = J_r^-1(dtheta).
  const auto& L = sqrt_information_;
  setJacobian<15, 3>(jacobians[0], L.middleCols<3>(0));
  const Eigen::Matrix<double, 15, 3> J_th = L.middleCols<3>(3) * geometry::rightJacobianInverseSO3(dtheta);
  setJacobian<15, 4>(jacobians[1], ambientFromTangent<15>(J_th, q));
  setJacobian<15, 3>(jacobians[2], L.middleCols<3>(6));
  setJacobian<15, 6>(jacobians[3], L.middleCols<6>(9));
  return true;
}

}  // namespace drover::backend
