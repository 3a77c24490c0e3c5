#include "backend/quaternion_manifold.hpp"

#include <cmath>
#include <numbers>

#include "geometry/so3.hpp"

namespace drover::backend {

namespace {
using RowMajor43 = Eigen::Matrix<double, 4, 3, Eigen::RowMajor>;
using RowMajor34 = Eigen::Matrix<double, 3, 4, Eigen::RowMajor>;
}  // namespace

Matrix43d quaternionPlusJacobian(const Eigen::Quaterniond& q) {
  // q (x) [dtheta / 2; 1]: vector part q_w dtheta/2 + q_v x dtheta/2, scalar part -q_v . dtheta/2.
  Matrix43d P;
  P.topRows<3>() = 0.5 * (q.w() * Eigen::Matrix3d::Identity() + geometry::hat(q.vec()));
  P.bottomRows<1>() = -0.5 * q.vec().transpose();
  return P;
}

bool RightQuaternionManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Eigen::Quaterniond> q(x);
  const Eigen::Map<const Eigen::Vector3d> d(delta);
  Eigen::Map<Eigen::Quaterniond> out(x_plus_delta);
  out = (q * geometry::expQuat(d)).normalized();  // normalised on write (ARCHITECTURE conventions)
  return true;
}

bool RightQuaternionManifold::PlusJacobian(const double* x, double* jacobian) const {
  const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(x).normalized();
  Eigen::Map<RowMajor43>{jacobian} = quaternionPlusJacobian(q);
  return true;
}

bool RightQuaternionManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Quaterniond qy = Eigen::Map<const Eigen::Quaterniond>(y).normalized();
  const Eigen::Quaterniond qx = Eigen::Map<const Eigen::Quaterniond>(x).normalized();
  Eigen::Map<Eigen::Vector3d>{y_minus_x} = geometry::logQuat(qx.conjugate() * qy);
  return true;
}

bool RightQuaternionManifold::MinusJacobian(const double* x, double* jacobian) const {
  // d Log(x^-1 y) / dy at y = x is the left inverse of P: 4 P^T (P^T P = I / 4, P^T x = 0).
  const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(x).normalized();
  Eigen::Map<RowMajor34>{jacobian} = 4.0 * quaternionPlusJacobian(q).transpose();
  return true;
}

// d (Exp(dpsi e_z) (x) q) / d dpsi at 0 = [e_z / 2; 0] (x) q = (-q_y, q_x, q_w, -q_z) / 2 in (x, y, z, w).
namespace {
Eigen::Vector4d worldYawPlusJacobian(const Eigen::Quaterniond& q) {
  return 0.5 * Eigen::Vector4d(-q.y(), q.x(), q.w(), -q.z());
}
}  // namespace

bool WorldYawManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Eigen::Quaterniond> q(x);
  Eigen::Map<Eigen::Quaterniond> out(x_plus_delta);
  out = (Eigen::Quaterniond(Eigen::AngleAxisd(delta[0], Eigen::Vector3d::UnitZ())) * q).normalized();
  return true;
}

bool WorldYawManifold::PlusJacobian(const double* x, double* jacobian) const {
  const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(x).normalized();
  Eigen::Map<Eigen::Vector4d>{jacobian} = worldYawPlusJacobian(q);
  return true;
}

bool WorldYawManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Quaterniond qy = Eigen::Map<const Eigen::Quaterniond>(y).normalized();
  const Eigen::Quaterniond qx = Eigen::Map<const Eigen::Quaterniond>(x).normalized();
  // The world-frame rotation from x to y; its angle about z (exact when y = Plus(x, dpsi), |dpsi| < pi).
  const Eigen::Quaterniond r = qy * qx.conjugate();
  y_minus_x[0] = 2.0 * std::atan2(r.z(), r.w());
  constexpr double kPi = std::numbers::pi;
  if (y_minus_x[0] > kPi) y_minus_x[0] -= 2 * kPi;
  if (y_minus_x[0] < -kPi) y_minus_x[0] += 2 * kPi;
  return true;
}

bool WorldYawManifold::MinusJacobian(const double* x, double* jacobian) const {
  // The left inverse of the plus Jacobian J (|J|^2 = 1/4): 4 J^T.
  const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(x).normalized();
  Eigen::Map<Eigen::Vector4d>{jacobian} = 4.0 * worldYawPlusJacobian(q);
  return true;
}

}  // namespace drover::backend
