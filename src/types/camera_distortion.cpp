// Lens distortion models on normalised image coordinates and their inverses by Newton's method.
// Radial-tangential: OpenCV's calib3d documentation and Kalibr's "radtan"; Brown, "Decentering Distortion of
// Lenses", Photogrammetric Engineering 32(3), 1966 (k1 k2 k3 radial, p1 p2 tangential).
// Equidistant: Kannala and Brandt, "A Generic Camera Model and Calibration Method for Conventional, Wide-Angle, and
// Fish-Eye Lenses", PAMI 28(8), 2006, Eq. (6) with four coefficients, as OpenCV's cv::fisheye and Kalibr.
#include "types/camera_distortion.hpp"

#include <cmath>
#include <numbers>

namespace drover {

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

Eigen::Vector2d distortRadTan(const CameraIntrinsics& intrinsics, const Eigen::Vector2d& xn, Eigen::Matrix2d* J) {
  const RadTan d = radTan(intrinsics);
  const double x = xn.x(), y = xn.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
  const Eigen::Vector2d xd(x * radial + 2.0 * d.p1 * x * y + d.p2 * (r2 + 2.0 * x * x),
                           y * radial + d.p1 * (r2 + 2.0 * y * y) + 2.0 * d.p2 * x * y);
  if (J) {
    const double dradial_dr2 = d.k1 + r2 * (2.0 * d.k2 + 3.0 * r2 * d.k3);
    (*J)(0, 0) = radial + 2.0 * x * x * dradial_dr2 + 2.0 * d.p1 * y + 6.0 * d.p2 * x;
    (*J)(0, 1) = 2.0 * x * y * dradial_dr2 + 2.0 * d.p1 * x + 2.0 * d.p2 * y;
    (*J)(1, 0) = 2.0 * x * y * dradial_dr2 + 2.0 * d.p1 * x + 2.0 * d.p2 * y;
    (*J)(1, 1) = radial + 2.0 * y * y * dradial_dr2 + 6.0 * d.p1 * y + 2.0 * d.p2 * x;
  }
  return xd;
}

// xd = s(r) xn with r = |xn|, s = theta_d(atan r) / r (-> 1 as r -> 0).
Eigen::Vector2d distortEquidistant(const CameraIntrinsics& intrinsics, const Eigen::Vector2d& xn,
                                   Eigen::Matrix2d* J) {
  const double r = xn.norm();
  if (r < 1e-12) {
    if (J) J->setIdentity();
    return xn;
  }
  const double theta = std::atan(r);
  double dthetad_dtheta = 0;
  const double theta_d = equidistantThetaD(intrinsics, theta, &dthetad_dtheta);
  const double s = theta_d / r;
  if (J) {
    // ds/dr = (theta_d' / (1 + r^2) - s) / r; d xd / d xn = s I + (ds/dr) xn xn^T / r.
    const double ds_dr = (dthetad_dtheta / (1.0 + r * r) - s) / r;
    *J = s * Eigen::Matrix2d::Identity() + (ds_dr / r) * xn * xn.transpose();
  }
  return s * xn;
}

}  // namespace

double equidistantThetaD(const CameraIntrinsics& intrinsics, double theta, double* dthetad_dtheta) {
  const auto& c = intrinsics.distortion_coeffs;
  const double k1 = c.size() > 0 ? c[0] : 0, k2 = c.size() > 1 ? c[1] : 0;
  const double k3 = c.size() > 2 ? c[2] : 0, k4 = c.size() > 3 ? c[3] : 0;
  const double t2 = theta * theta;
  const double poly = 1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4)));
  if (dthetad_dtheta) *dthetad_dtheta = 1.0 + t2 * (3.0 * k1 + t2 * (5.0 * k2 + t2 * (7.0 * k3 + t2 * 9.0 * k4)));
  return theta * poly;
}

std::optional<double> equidistantTheta(const CameraIntrinsics& intrinsics, double theta_d, double tolerance) {
  double theta = theta_d;
  for (int iteration = 0; iteration < 50; ++iteration) {
    double derivative = 0;
    const double residual = equidistantThetaD(intrinsics, theta, &derivative) - theta_d;
    if (!std::isfinite(residual)) return std::nullopt;
    if (std::abs(residual) < tolerance) {
      if (theta < 0 || theta >= std::numbers::pi) return std::nullopt;
      return theta;
    }
    if (!(derivative > 1e-12)) return std::nullopt;  // past the fold of the polynomial
    theta -= residual / derivative;
  }
  return std::nullopt;
}

Eigen::Vector2d distortNormalized(const CameraIntrinsics& intrinsics, const Eigen::Vector2d& xn,
                                  Eigen::Matrix2d* J_xd_xn) {
  switch (intrinsics.distortion) {
    case DistortionModel::kRadialTangential:
      return distortRadTan(intrinsics, xn, J_xd_xn);
    case DistortionModel::kEquidistant:
      return distortEquidistant(intrinsics, xn, J_xd_xn);
    case DistortionModel::kNone:
      break;
  }
  if (J_xd_xn) J_xd_xn->setIdentity();
  return xn;
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

}  // namespace drover
