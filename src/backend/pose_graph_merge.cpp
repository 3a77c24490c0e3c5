#include "backend/pose_graph_merge.hpp"

#include <stdexcept>
#include <string>

#include "geometry/so3.hpp"

namespace drover::backend {
namespace {

Matrix6d symmetric(const Matrix6d& m) { return 0.5 * (m + m.transpose()); }

}  // namespace

PoseGraphEdge moveFromEnd(const PoseGraphEdge& e, int into, const Eigen::Isometry3d& T_from_into) {
  PoseGraphEdge out = e;
  out.from = into;
  out.T_from_to_measured = T_from_into.inverse() * e.T_from_to_measured;
  // r' = A r, A = diag(R^T, I) orthogonal: I' = A^-T I A^-1 = A I A^T.
  Matrix6d A = Matrix6d::Identity();
  A.topLeftCorner<3, 3>() = T_from_into.linear().transpose();
  out.information = symmetric(A * e.information * A.transpose());
  return out;
}

PoseGraphEdge moveToEnd(const PoseGraphEdge& e, int into, const Eigen::Isometry3d& T_to_into) {
  PoseGraphEdge out = e;
  if (e.kind == EdgeKind::kPrior) out.from = into;
  out.to = into;
  out.T_from_to_measured = e.T_from_to_measured * T_to_into;
  // r_t' = r_t + (R_a^T R_b - R_m) t_x with R_a^T R_b = R_m Exp(r_phi) ~ R_m (I + [r_phi]x): r_t - R_m [t_x]x r_phi;
  // r_phi' = Log(R_x^T R_m^T R_X R_x) = R_x^T r_phi.
  Matrix6d A = Matrix6d::Identity();
  A.topRightCorner<3, 3>() = -e.T_from_to_measured.linear() * geometry::hat(T_to_into.translation());
  A.bottomRightCorner<3, 3>() = T_to_into.linear().transpose();
  const Matrix6d A_inv = A.inverse();
  out.information = symmetric(A_inv.transpose() * e.information * A_inv);
  return out;
}

PoseGraphEdge fuseParallel(const PoseGraphEdge& a, const PoseGraphEdge& b) {
  if (a.from != b.from || a.to != b.to || a.kind != b.kind)
    throw std::invalid_argument("fuseParallel: edges " + std::to_string(a.from) + " -> " + std::to_string(a.to) +
                                " and " + std::to_string(b.from) + " -> " + std::to_string(b.to) +
                                " are not parallel edges of one kind");
  const Eigen::Matrix3d& R_a = a.T_from_to_measured.linear();
  Eigen::Matrix<double, 6, 1> d;
  d.head<3>() = b.T_from_to_measured.translation() - a.T_from_to_measured.translation();
  d.tail<3>() = geometry::logSO3(R_a.transpose() * b.T_from_to_measured.linear());
  const Matrix6d information = symmetric(a.information + b.information);
  const Eigen::Matrix<double, 6, 1> delta = information.ldlt().solve(b.information * d);
  PoseGraphEdge out = a;
  out.T_from_to_measured.linear() = R_a * geometry::expSO3(delta.tail<3>());
  out.T_from_to_measured.translation() = a.T_from_to_measured.translation() + delta.head<3>();
  out.information = information;
  return out;
}

}  // namespace drover::backend
