#pragma once
// SO(3) helpers on Eigen types. Conventions follow Forster et al., "On-Manifold Preintegration" (TRO 2017):
// Exp: R^3 -> SO(3) (their Eq. 3), Log its inverse, right Jacobian J_r (Eq. 8) with
//   Exp(phi + dphi) ~= Exp(phi) Exp(J_r(phi) dphi),   Log(Exp(phi) Exp(dphi)) ~= phi + J_r^-1(phi) dphi.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace drover::geometry {

// [v]_x: the skew-symmetric matrix with hat(v) * w == v.cross(w).
Eigen::Matrix3d hat(const Eigen::Vector3d& v);
Eigen::Vector3d vee(const Eigen::Matrix3d& S);

// Rodrigues' formula; exact near zero (Taylor expansion below 1e-8 rad).
Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi);
Eigen::Quaterniond expQuat(const Eigen::Vector3d& phi);
// Rotation vector with angle in [0, pi]; stable near 0 and near pi.
Eigen::Vector3d logSO3(const Eigen::Matrix3d& R);
Eigen::Vector3d logQuat(const Eigen::Quaterniond& q);

Eigen::Matrix3d rightJacobianSO3(const Eigen::Vector3d& phi);
Eigen::Matrix3d rightJacobianInverseSO3(const Eigen::Vector3d& phi);
// J_l(phi) = J_r(-phi).
Eigen::Matrix3d leftJacobianSO3(const Eigen::Vector3d& phi);
Eigen::Matrix3d leftJacobianInverseSO3(const Eigen::Vector3d& phi);

// Geodesic interpolation R0 Exp(alpha Log(R0^T R1)), alpha in [0, 1] (slerp).
Eigen::Quaterniond slerp(const Eigen::Quaterniond& q0, const Eigen::Quaterniond& q1, double alpha);

// Rotation angle of R [rad], in [0, pi].
double rotationAngle(const Eigen::Matrix3d& R);

// Heading of R [rad]: the yaw of its x axis about the z axis, atan2(R10, R00), in (-pi, pi].
double yawOf(const Eigen::Matrix3d& R);
// R_tilt turned about the z axis until its heading is R_heading's: the tilt (roll, pitch) of one rotation with the
// heading of the other. For ground robots (|pitch| well below 90 deg).
Eigen::Matrix3d withRollPitchOf(const Eigen::Matrix3d& R_heading, const Eigen::Matrix3d& R_tilt);

// Projects a nearly orthonormal matrix (e.g. parsed from 12 printed numbers) to the closest rotation (SVD).
Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& M);

}  // namespace drover::geometry
