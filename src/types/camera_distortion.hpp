#pragma once
// Lens distortion on normalised image coordinates, shared by the simulator's renderer (src/sim) and the visual
// front end's camera models (src/visual): one implementation of the maths, in the core both may depend on.
#include <Eigen/Core>
#include <optional>

#include "types/calibration.hpp"

namespace drover {

// Radial-tangential (Brown-Conrady, as OpenCV and Kalibr "radtan") on normalised coordinates xn = (x / z, y / z):
// r2 = |xn|^2, radial = 1 + k1 r2 + k2 r2^2 + k3 r2^3,
//   xd = x radial + 2 p1 x y + p2 (r2 + 2 x^2),   yd = y radial + p1 (r2 + 2 y^2) + 2 p2 x y.
// Equidistant (Kannala-Brandt as OpenCV fisheye and Kalibr "equidistant"): theta = atan(|xn|),
//   theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8),  xd = (theta_d / |xn|) xn
// (valid for points in front of the camera; see visual::CameraModel for rays beyond 90 deg).
// J_xd_xn, when given, receives the Jacobian d xd / d xn. kNone returns xn (J = identity).
Eigen::Vector2d distortNormalized(const CameraIntrinsics& intrinsics, const Eigen::Vector2d& xn,
                                  Eigen::Matrix2d* J_xd_xn = nullptr);
// Inverse of distortNormalized by Newton's method started at xd; nothing when |distort(xn) - xd| does not fall
// below `tolerance` (normalised units) within 50 iterations.
std::optional<Eigen::Vector2d> undistortNormalized(const CameraIntrinsics& intrinsics, const Eigen::Vector2d& xd,
                                                   double tolerance);

// Equidistant: theta_d(theta) = theta (1 + k1 theta^2 + ... + k4 theta^8) and its derivative d theta_d / d theta.
double equidistantThetaD(const CameraIntrinsics& intrinsics, double theta, double* dthetad_dtheta = nullptr);
// Inverse of equidistantThetaD by Newton's method on [0, pi); nothing when it does not converge to `tolerance`
// [rad] or the polynomial folds (derivative <= 0) before reaching theta_d.
std::optional<double> equidistantTheta(const CameraIntrinsics& intrinsics, double theta_d, double tolerance);

}  // namespace drover
