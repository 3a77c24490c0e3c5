// Radial-tangential (Brown-Conrady) lens distortion and its inverse by Newton's method, on normalised image
// coordinates. Model as in OpenCV's calib3d documentation and Kalibr's "radtan": Brown, "Decentering Distortion
// of Lenses", Photogrammetric Engineering 32(3), 1966, Eqs. (with k1 k2 k3 radial and p1 p2 tangential terms).
#include <cmath>

#include "sim/camera_model.hpp"

namespace drover::sim {

namespace {

struct RadTan {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
};

RadTan radTan(const CameraIntrinsics& intrinsics) {
  const auto& c = intrinsics.distortion_coeffs;
  RadTan d;
  if (c.size() >= 4) {
    d.k1 = c[0];
    d.k2 = c[1];
    d.p1 = c[2];
    d.p2 = c[3];
  }
  if (c.size() >= 5) d.k3 = c[4];
  return d;
}

}  // namespace

Eigen::Vector2d distortNormalized(const CameraIntrinsics& intrinsics, const Eigen::Vector2d& xn,
                                  Eigen::Matrix2d* J_xd_xn) {
  if (intrinsics.distortion != DistortionModel::kRadialTangential) {
    if (J_xd_xn) J_xd_xn->setIdentity();
    return xn;
  }
  const RadTan d = radTan(intrinsics);
  const double x = xn.x(), y = xn.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
  const Eigen::Vector2d xd(x * radial + 2.0 * d.p1 * x * y + d.p2 * (r2 + 2.0 * x * x),
                           y * radial + d.p1 * (r2 + 2.0 * y * y) + 2.0 * d.p2 * x * y);
  if (J_xd_xn) {
    const double dradial_dr2 = d.k1 + r2 * (2.0 * d.k2 + 3.0 * r2 * d.k3);
    (*J_xd_xn)(0, 0) = radial + 2.0 * x * x * dradial_dr2 + 2.0 * d.p1 * y + 6.0 * d.p2 * x;
    (*J_xd_xn)(0, 1) = 2.0 * x * y * dradial_dr2 + 2.0 * d.p1 * x + 2.0 * d.p2 * y;
    (*J_xd_xn)(1, 0) = 2.0 * x * y * dradial_dr2 + 2.0 * d.p1 * x + 2.0 * d.p2 * y;
    (*J_xd_xn)(1, 1) = radial + 2.0 * y * y * dradial_dr2 + 6.0 * d.p1 * y + 2.0 * d.p2 * x;
  }
  return xd;
}

std::optional<Eigen::Vector2d> undistortNormalized(const CameraIntrinsics& intrinsics, const Eigen::Vector2d& xd,
                                                   double tolerance) {
  Eigen::Vector2d xn = xd;  // the distortion is a small perturbation of the identity near the image
  Eigen::Matrix2d J;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Eigen::Vector2d residual = distortNormalized(intrinsics, xn, &J) - xd;
    if (!residual.allFinite()) return std::nullopt;
    if (residual.norm() < tolerance) return xn;
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-12)) return std::nullopt;  // fold of the model: not invertible here
    xn -= J.inverse() * residual;
  }
  return std::nullopt;
}

}  // namespace drover::sim
