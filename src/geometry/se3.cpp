#include "geometry/se3.hpp"

#include <cmath>

#include "geometry/so3.hpp"

namespace drover::geometry {

Eigen::Isometry3d makeIsometry(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

Eigen::Isometry3d makeIsometry(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) {
  return makeIsometry(q.normalized().toRotationMatrix(), t);
}

Eigen::Isometry3d inverse(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d Rt = T.linear().transpose();
  return makeIsometry(Rt, -Rt * T.translation());
}

Eigen::Isometry3d expSE3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  return makeIsometry(expSO3(phi), leftJacobianSO3(phi) * rho);
}

Vector6d logSE3(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d phi = logSO3(T.linear());
  Vector6d xi;
  xi.head<3>() = leftJacobianInverseSO3(phi) * T.translation();
  xi.tail<3>() = phi;
  return xi;
}

Matrix6d adjointSE3(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  Matrix6d Ad = Matrix6d::Zero();
  Ad.topLeftCorner<3, 3>() = R;
  Ad.topRightCorner<3, 3>() = hat(T.translation()) * R;
  Ad.bottomRightCorner<3, 3>() = R;
  return Ad;
}

namespace {
// Q(rho, phi) of Barfoot Eq. 7.86: the off-diagonal block of the left Jacobian of SE(3).
Eigen::Matrix3d qBlock(const Eigen::Vector3d& rho, const Eigen::Vector3d& phi) {
  const double th = phi.norm();
  const Eigen::Matrix3d P = hat(phi);
  const Eigen::Matrix3d R = hat(rho);
  const Eigen::Matrix3d PR = P * R, RP = R * P, PRP = P * R * P;
  if (th < 1e-3) {  // cancellation in the closed form exceeds the series' truncation error
    // Series limits of the coefficients below.
    return 0.5 * R + (PR + RP + PRP) / 6.0 + (P * PR + RP * P - 3.0 * PRP) / 24.0 + (PRP * P + P * PRP) / 120.0;
  }
  const double t2 = th * th, t3 = t2 * th, t4 = t3 * th, t5 = t4 * th;
  const double s = std::sin(th), c = std::cos(th);
  const double a = (th - s) / t3;
  const double b = (t2 + 2.0 * c - 2.0) / (2.0 * t4);
  const double d = (2.0 * th - 3.0 * s + th * c) / (2.0 * t5);
  return 0.5 * R + a * (PR + RP + PRP) + b * (P * PR + RP * P - 3.0 * PRP) + d * (PRP * P + P * PRP);
}

Matrix6d leftJacobianSE3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>(), phi = xi.tail<3>();
  const Eigen::Matrix3d Jl = leftJacobianSO3(phi);
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = Jl;
  J.topRightCorner<3, 3>() = qBlock(rho, phi);
  J.bottomRightCorner<3, 3>() = Jl;
  return J;
}

Matrix6d leftJacobianInverseSE3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>(), phi = xi.tail<3>();
  const Eigen::Matrix3d Jli = leftJacobianInverseSO3(phi);
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = Jli;
  J.topRightCorner<3, 3>() = -Jli * qBlock(rho, phi) * Jli;
  J.bottomRightCorner<3, 3>() = Jli;
  return J;
}
}  // namespace

// J_r(xi) = J_l(-xi).
Matrix6d rightJacobianSE3(const Vector6d& xi) { return leftJacobianSE3(-xi); }
Matrix6d rightJacobianInverseSE3(const Vector6d& xi) { return leftJacobianInverseSE3(-xi); }

Eigen::Isometry3d interpolate(const Eigen::Isometry3d& T0, const Eigen::Isometry3d& T1, double alpha) {
  const Eigen::Quaterniond q = slerp(Eigen::Quaterniond(T0.linear()), Eigen::Quaterniond(T1.linear()), alpha);
  const Eigen::Vector3d t = (1.0 - alpha) * T0.translation() + alpha * T1.translation();
  return makeIsometry(q, t);
}

Eigen::Isometry3d interpolateGeodesic(const Eigen::Isometry3d& T0, const Eigen::Isometry3d& T1, double alpha) {
  return T0 * expSE3(alpha * logSE3(inverse(T0) * T1));
}

}  // namespace drover::geometry
