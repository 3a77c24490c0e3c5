#include "geometry/so3.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace drover::geometry {

namespace {
constexpr double kSmallAngle = 1e-8;  // [rad] below this, first/second-order Taylor terms are exact in double
}

Eigen::Matrix3d hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

Eigen::Vector3d vee(const Eigen::Matrix3d& S) { return {S(2, 1), S(0, 2), S(1, 0)}; }

Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi) { return expQuat(phi).toRotationMatrix(); }

Eigen::Quaterniond expQuat(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  if (theta < kSmallAngle) {
    // q = [1, phi/2] to second order; normalise to stay on the manifold.
    Eigen::Quaterniond q(1.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z());
    return q.normalized();
  }
  const double half = 0.5 * theta;
  const Eigen::Vector3d axis = phi / theta;
  const double s = std::sin(half);
  return Eigen::Quaterniond(std::cos(half), s * axis.x(), s * axis.y(), s * axis.z());
}

Eigen::Vector3d logQuat(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // same rotation, angle in [0, pi]
  const double sin_half = q.vec().norm();
  if (sin_half < kSmallAngle) return 2.0 * q.vec() / q.w();
  // atan2 is accurate for all angles, unlike acos(w) near 0 or asin near pi.
  const double theta = 2.0 * std::atan2(sin_half, q.w());
  return theta / sin_half * q.vec();
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& R) { return logQuat(Eigen::Quaterniond(R)); }

Eigen::Matrix3d rightJacobianSO3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d W = hat(phi);
  if (theta < 1e-5) return Eigen::Matrix3d::Identity() - 0.5 * W + W * W / 6.0;
  const double t2 = theta * theta;
  // Forster Eq. 8.
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(theta)) / t2 * W + (theta - std::sin(theta)) / (t2 * theta) * W * W;
}

Eigen::Matrix3d rightJacobianInverseSO3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d W = hat(phi);
  if (theta < 1e-5) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 12.0;
  const double t2 = theta * theta;
  // Forster Eq. 9.
  const double c = 1.0 / t2 - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() + 0.5 * W + c * W * W;
}

Eigen::Matrix3d leftJacobianSO3(const Eigen::Vector3d& phi) { return rightJacobianSO3(-phi); }
Eigen::Matrix3d leftJacobianInverseSO3(const Eigen::Vector3d& phi) { return rightJacobianInverseSO3(-phi); }

Eigen::Quaterniond slerp(const Eigen::Quaterniond& q0, const Eigen::Quaterniond& q1, double alpha) {
  const Eigen::Vector3d delta = logQuat(q0.conjugate() * q1);
  return (q0 * expQuat(alpha * delta)).normalized();
}

double rotationAngle(const Eigen::Matrix3d& R) { return logSO3(R).norm(); }

double yawOf(const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); }

Eigen::Matrix3d withRollPitchOf(const Eigen::Matrix3d& R_heading, const Eigen::Matrix3d& R_tilt) {
  return Eigen::AngleAxisd(yawOf(R_heading) - yawOf(R_tilt), Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_tilt;
}

Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

}  // namespace drover::geometry
