#include "backend/ground_factor.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "backend/jacobian_util.hpp"
#include "geometry/so3.hpp"

namespace drover::backend {

GroundHeightFactor::GroundHeightFactor(const Eigen::Vector2d& obs, double height_m, double sigma_m)
    : ray_(obs.x(), obs.y(), 1.0), height_(height_m), weight_(1.0 / sigma_m) {
  if (!obs.allFinite() || !(std::isfinite(height_m) && height_m > 0) || !(std::isfinite(sigma_m) && sigma_m > 0))
    throw std::invalid_argument("GroundHeightFactor: height = " + std::to_string(height_m) + " m, sigma = " +
                                std::to_string(sigma_m) + " m must be finite and > 0, obs finite");
}

bool GroundHeightFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> p_ic(parameters[0]);
  const Eigen::Quaterniond q_ic = Eigen::Map<const Eigen::Quaterniond>(parameters[1]).normalized();
  const double lambda = parameters[2][0];
  if (!(std::abs(lambda) > 0)) return false;
  const Eigen::Matrix3d R_ic = q_ic.toRotationMatrix();
  const Eigen::Vector3d P_c = ray_ / lambda;  // [m] in the anchor camera
  residuals[0] = weight_ * ((R_ic * P_c + p_ic).z() + height_);
  if (!std::isfinite(residuals[0])) return false;
  if (jacobians == nullptr) return true;
  const Eigen::RowVector3d e_z_R = weight_ * R_ic.row(2);  // weight * e_z^T R_ic
  setJacobian<1, 3>(jacobians[0], weight_ * Eigen::RowVector3d::UnitZ());
  // R Exp(dtheta) x = R x - R hat(x) dtheta (right perturbation, as the other factors).
  if (jacobians[1] != nullptr) {
    const Eigen::Matrix<double, 1, 3> J_tangent = -e_z_R * geometry::hat(P_c);
    setJacobian<1, 4>(jacobians[1], ambientFromTangent<1>(J_tangent, q_ic));
  }
  // d P_c / d lambda = -ray / lambda^2 = -P_c / lambda.
  setJacobian<1, 1>(jacobians[2], Eigen::Matrix<double, 1, 1>(-e_z_R * P_c / lambda));
  return true;
}

}  // namespace drover::backend
