#pragma once
// A Gaussian prior on one full navigation state, linear in the state's tangent space at a fixed linearisation
// point x_lin (the form a marginalisation leaves behind, Sibley et al. 2010; Leutenegger et al., OKVIS, 2015):
//   r = offset + L dx,   dx = [p - p_lin; Log(R_lin^T R); v - v_lin; b - b_lin]  (15 = 3 + 3 + 3 + 6),
// units [m], [rad], [m/s], [rad/s, m/s^2]. With offset = 0 and L = diag(1 / sigma) it is an ordinary prior
// (used for the first state); with L = sqrt(S) V^T and offset = sqrt(S)^-1 V^T b from a Schur complement it is
// the marginalisation prior. Blocks: p (3), q (4, RightQuaternionManifold), v (3), bias (6). Backend-internal.
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "backend/imu_factors.hpp"

namespace drover::backend {

using Matrix15d = Eigen::Matrix<double, 15, 15>;
using Vector15d = Eigen::Matrix<double, 15, 1>;

// A navigation state as the backend's parameter blocks hold it.
struct StatePoint {
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();                // [m]
  Eigen::Quaterniond q_world_imu = Eigen::Quaterniond::Identity();  // unit
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();                // [m/s]
  Vector6d bias = Vector6d::Zero();                                 // [b_g rad/s; b_a m/s^2]
};

class NavStatePriorFactor final : public ceres::SizedCostFunction<15, 3, 4, 3, 6> {
 public:
  // Throws std::invalid_argument when any input is not finite.
  NavStatePriorFactor(const StatePoint& linearization, const Matrix15d& sqrt_information,
                      const Vector15d& offset = Vector15d::Zero());
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  const StatePoint& linearization() const { return lin_; }
  const Matrix15d& sqrtInformation() const { return sqrt_information_; }
  const Vector15d& offset() const { return offset_; }

 private:
  StatePoint lin_;
  Matrix15d sqrt_information_;
  Vector15d offset_;
};

}  // namespace drover::backend
