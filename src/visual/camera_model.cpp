// Pinhole (rad-tan) and equidistant camera models. Equidistant projection works on the angle from the optical axis,
// theta = atan2(|(x, y)|, z) (Kannala-Brandt, PAMI 2006, Eq. 6), so rays beyond 90 degrees project as well.
#include "visual/camera_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "types/camera_distortion.hpp"

namespace drover::visual {

namespace {

bool finite(double x) { return std::isfinite(x); }

// Largest theta < pi up to which theta_d(theta) increases (the model is invertible), sampled finely.
double equidistantMaxTheta(const CameraIntrinsics& k) {
  constexpr int kSteps = 3140;
  for (int i = 1; i < kSteps; ++i) {
    const double theta = std::numbers::pi * i / kSteps;
    double derivative = 0;
    equidistantThetaD(k, theta, &derivative);
    if (!(derivative > 1e-6)) return std::numbers::pi * (i - 1) / kSteps;
  }
  return std::numbers::pi * (kSteps - 1) / kSteps;
}

}  // namespace

std::string validateIntrinsics(const CameraIntrinsics& k) {
  if (k.width <= 0 || k.height <= 0)
    return "camera size must be positive, got " + std::to_string(k.width) + "x" + std::to_string(k.height);
  if (!(k.fx > 0) || !(k.fy > 0) || !finite(k.fx) || !finite(k.fy))
    return "focal lengths must be positive and finite, got fx = " + std::to_string(k.fx) +
           ", fy = " + std::to_string(k.fy);
  if (!finite(k.cx) || !finite(k.cy)) return "principal point must be finite";
  for (double c : k.distortion_coeffs)
    if (!finite(c)) return "distortion coefficients must be finite";
  const std::size_t n = k.distortion_coeffs.size();
  switch (k.distortion) {
    case DistortionModel::kRadialTangential:
      if (n != 4 && n != 5) return "radial-tangential needs 4 or 5 coefficients, got " + std::to_string(n);
      break;
    case DistortionModel::kEquidistant:
      if (n != 4) return "equidistant needs 4 coefficients, got " + std::to_string(n);
      break;
    case DistortionModel::kNone:
      if (n != 0 &&
          std::any_of(k.distortion_coeffs.begin(), k.distortion_coeffs.end(), [](double c) { return c != 0; }))
        return "distortion model none with non-zero coefficients";
      break;
  }
  return {};
}

CameraModel::CameraModel(const CameraIntrinsics& intrinsics) : intrinsics_(intrinsics) {
  if (const std::string error = validateIntrinsics(intrinsics); !error.empty())
    throw std::invalid_argument("CameraModel: " + error);
  tolerance_ = 1e-9 / std::max(intrinsics.fx, intrinsics.fy);
  if (intrinsics.distortion == DistortionModel::kEquidistant) {
    max_theta_ = equidistantMaxTheta(intrinsics);
    return;
  }
  // Pinhole: accept points up to 1.2x the radius of the image border (rad-tan folds somewhere outside it, and
  // a point beyond the fold would project to a wrong, in-image pixel).
  max_r2_ = std::numeric_limits<double>::infinity();
  if (intrinsics.distortion != DistortionModel::kRadialTangential) return;
  double border_r2 = 0;
  const double w = intrinsics.width, h = intrinsics.height;
  for (int i = 0; i <= 64; ++i) {
    const double s = i / 64.0;
    for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(s * w - 0.5, -0.5), Eigen::Vector2d(s * w - 0.5, h - 0.5),
                                         Eigen::Vector2d(-0.5, s * h - 0.5), Eigen::Vector2d(w - 0.5, s * h - 0.5)}) {
      const Eigen::Vector2d xd((pixel.x() - intrinsics.cx) / intrinsics.fx,
                               (pixel.y() - intrinsics.cy) / intrinsics.fy);
      const auto xn = undistortNormalized(intrinsics, xd, tolerance_);
      if (!xn) return;  // not invertible at the border: leave the radius unlimited
      border_r2 = std::max(border_r2, xn->squaredNorm());
    }
  }
  max_r2_ = 1.44 * border_r2;
}

std::optional<Eigen::Vector2d> CameraModel::project(const Eigen::Vector3d& p_cam,
                                                    Eigen::Matrix<double, 2, 3>* J_pixel_point) const {
  const CameraIntrinsics& k = intrinsics_;
  if (!p_cam.allFinite()) return std::nullopt;
  Eigen::Vector2d xd;
  Eigen::Matrix<double, 2, 3> J_xd_p;
  if (k.distortion == DistortionModel::kEquidistant) {
    const double rho = p_cam.head<2>().norm();
    const double theta = std::atan2(rho, p_cam.z());
    if (theta > max_theta_ || p_cam.norm() < 1e-9) return std::nullopt;
    if (rho < 1e-12) {  // on the axis: the model is the pinhole to first order
      xd = p_cam.head<2>() / p_cam.z();
      J_xd_p << 1 / p_cam.z(), 0, -p_cam.x() / (p_cam.z() * p_cam.z()), 0, 1 / p_cam.z(),
          -p_cam.y() / (p_cam.z() * p_cam.z());
    } else {
      double dthetad = 0;
      const double theta_d = equidistantThetaD(k, theta, &dthetad);
      const Eigen::Vector2d dir = p_cam.head<2>() / rho;
      xd = theta_d * dir;
      // d theta / d p = (z x / rho, z y / rho, -rho) / |p|^2; d dir / d (x, y) = (I - dir dir^T) / rho.
      const double n2 = p_cam.squaredNorm();
      const Eigen::RowVector3d dtheta(p_cam.z() * dir.x() / n2, p_cam.z() * dir.y() / n2, -rho / n2);
      J_xd_p = dir * dthetad * dtheta;
      J_xd_p.leftCols<2>() += theta_d * (Eigen::Matrix2d::Identity() - dir * dir.transpose()) / rho;
    }
  } else {
    if (p_cam.z() <= 1e-9) return std::nullopt;
    const Eigen::Vector2d xn = p_cam.head<2>() / p_cam.z();
    if (xn.squaredNorm() > max_r2_) return std::nullopt;
    Eigen::Matrix2d J_xd_xn;
    xd = distortNormalized(k, xn, &J_xd_xn);
    Eigen::Matrix<double, 2, 3> J_xn_p;
    J_xn_p << 1, 0, -xn.x(), 0, 1, -xn.y();
    J_xd_p = J_xd_xn * J_xn_p / p_cam.z();
  }
  if (J_pixel_point) {
    *J_pixel_point = J_xd_p;
    J_pixel_point->row(0) *= k.fx;
    J_pixel_point->row(1) *= k.fy;
  }
  return Eigen::Vector2d(k.fx * xd.x() + k.cx, k.fy * xd.y() + k.cy);
}

std::optional<Eigen::Vector3d> CameraModel::unproject(const Eigen::Vector2d& pixel) const {
  const CameraIntrinsics& k = intrinsics_;
  if (!pixel.allFinite()) return std::nullopt;
  const Eigen::Vector2d xd((pixel.x() - k.cx) / k.fx, (pixel.y() - k.cy) / k.fy);
  if (k.distortion == DistortionModel::kEquidistant) {
    const double theta_d = xd.norm();
    if (theta_d < 1e-15) return Eigen::Vector3d::UnitZ();
    const auto theta = equidistantTheta(k, theta_d, tolerance_);
    if (!theta || *theta > max_theta_) return std::nullopt;
    const Eigen::Vector2d dir = xd / theta_d;
    return Eigen::Vector3d(std::sin(*theta) * dir.x(), std::sin(*theta) * dir.y(), std::cos(*theta));
  }
  const auto xn = undistortNormalized(k, xd, tolerance_);
  if (!xn) return std::nullopt;
  return Eigen::Vector3d(xn->x(), xn->y(), 1.0).normalized();
}

std::optional<Eigen::Vector2d> CameraModel::undistort(const Eigen::Vector2d& pixel) const {
  const auto ray = unproject(pixel);
  if (!ray || ray->z() <= 1e-9) return std::nullopt;
  return Eigen::Vector2d(ray->x() / ray->z(), ray->y() / ray->z());
}

std::vector<cv::Point2f> CameraModel::undistortPoints(const std::vector<cv::Point2f>& pixels) const {
  std::vector<cv::Point2f> out;
  out.reserve(pixels.size());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const cv::Point2f& p : pixels) {
    const auto xn = undistort(Eigen::Vector2d(p.x, p.y));
    out.push_back(xn ? cv::Point2f(static_cast<float>(xn->x()), static_cast<float>(xn->y())) : cv::Point2f(nan, nan));
  }
  return out;
}

cv::Mat CameraModel::cameraMatrix() const {
  return (cv::Mat_<double>(3, 3) << intrinsics_.fx, 0, intrinsics_.cx, 0, intrinsics_.fy, intrinsics_.cy, 0, 0, 1);
}

cv::Mat CameraModel::distortionCoefficients() const {
  cv::Mat d(1, static_cast<int>(intrinsics_.distortion_coeffs.size()), CV_64F);
  for (std::size_t i = 0; i < intrinsics_.distortion_coeffs.size(); ++i)
    d.at<double>(0, static_cast<int>(i)) = intrinsics_.distortion_coeffs[i];
  return d;
}

}  // namespace drover::visual
