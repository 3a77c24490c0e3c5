#pragma once
// Writing Eigen Jacobians into Ceres' row-major output arrays (backend-internal).
#include <Eigen/Core>

#include "backend/quaternion_manifold.hpp"

namespace drover::backend {

// Ceres asks for a block's Jacobian only when that block is not constant: a null pointer means "skip".
template <int Rows, int Cols, typename Derived>
void setJacobian(double* out, const Eigen::MatrixBase<Derived>& J) {
  if (out == nullptr) return;
  Eigen::Map<Eigen::Matrix<double, Rows, Cols, Cols == 1 ? Eigen::ColMajor : Eigen::RowMajor>>{out} = J;
}

}  // namespace drover::backend
