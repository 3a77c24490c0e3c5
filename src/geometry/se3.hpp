#pragma once
// SE(3) helpers on Eigen::Isometry3d. Tangent vectors are ordered xi = [rho; phi] (translation part first,
// then rotation), T = Exp(xi) = [Exp(phi), J_l(phi) rho; 0, 1] (Barfoot, "State Estimation for Robotics",
// Eq. 7.85). Poses are named T_to_from: T_world_lidar maps lidar-frame points into the world frame.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace drover::geometry {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

Eigen::Isometry3d expSE3(const Vector6d& xi);
Vector6d logSE3(const Eigen::Isometry3d& T);

// Builds an isometry from a rotation and translation; the rotation is used as given.
Eigen::Isometry3d makeIsometry(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);
Eigen::Isometry3d makeIsometry(const Eigen::Quaterniond& q, const Eigen::Vector3d& t);

// Inverse of a rigid transform without a general 4x4 inversion.
Eigen::Isometry3d inverse(const Eigen::Isometry3d& T);

// Adjoint Ad_T with xi ordered [rho; phi]: T Exp(xi) T^-1 = Exp(Ad_T xi).
Matrix6d adjointSE3(const Eigen::Isometry3d& T);

// Right Jacobian of SE(3) and its inverse (Barfoot Eq. 7.95 with the [rho; phi] ordering):
//   Exp(xi + dxi) ~= Exp(xi) Exp(J_r(xi) dxi).
Matrix6d rightJacobianSE3(const Vector6d& xi);
Matrix6d rightJacobianInverseSE3(const Vector6d& xi);

// Interpolation used for deskewing and trajectory lookup: slerp on rotation, linear on translation,
// alpha in [0, 1] (alpha outside extrapolates).
Eigen::Isometry3d interpolate(const Eigen::Isometry3d& T0, const Eigen::Isometry3d& T1, double alpha);
// Geodesic interpolation on SE(3): T0 Exp(alpha Log(T0^-1 T1)) (screw motion).
Eigen::Isometry3d interpolateGeodesic(const Eigen::Isometry3d& T0, const Eigen::Isometry3d& T1, double alpha);

}  // namespace drover::geometry
