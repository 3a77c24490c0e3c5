#include "lidar/scan_matcher_residual.hpp"

#include <Eigen/Eigenvalues>

#include "geometry/so3.hpp"

namespace drover::lidar::detail {
namespace {

// Mean and covariance (divided by count, as LIO-SAM) of the neighbours, eigen-decomposed (ascending values).
Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> neighbourEigen(const Eigen::Vector3d* points, int count,
                                                               Eigen::Vector3d& mean) {
  mean.setZero();
  for (int i = 0; i < count; ++i) mean += points[i];
  mean /= count;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d d = points[i] - mean;
    cov += d * d.transpose();
  }
  cov /= count;
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov);
}

}  // namespace

FeatureFit fitLine(const Eigen::Vector3d* points, int count, double eigen_ratio) {
  FeatureFit fit;
  if (count < 2) return fit;
  const auto eig = neighbourEigen(points, count, fit.anchor);
  const Eigen::Vector3d values = eig.eigenvalues();
  if (!(values(2) > eigen_ratio * values(1)) || values(2) <= 0.0) return fit;
  fit.direction = eig.eigenvectors().col(2).normalized();
  // The other two eigenvectors are orthonormal and orthogonal to the direction.
  fit.normals.row(0) = eig.eigenvectors().col(0).normalized().transpose();
  fit.normals.row(1) = fit.direction.cross(eig.eigenvectors().col(0)).normalized().transpose();
  fit.rows = 2;
  fit.valid = true;
  return fit;
}

FeatureFit fitPlane(const Eigen::Vector3d* points, int count, double tolerance, double min_aspect) {
  FeatureFit fit;
  if (count < 3) return fit;
  const auto eig = neighbourEigen(points, count, fit.anchor);
  const Eigen::Vector3d values = eig.eigenvalues();
  // Collinear neighbours span no plane: the middle eigenvalue would be ~0.
  if (!(values(1) > 1e-6 * values(2)) || values(2) <= 0.0) return fit;
  // A thin strip (one scan ring's arc) fixes its normal only through its curvature: the normal may turn about it.
  if (values(1) < min_aspect * min_aspect * values(2)) return fit;
  fit.direction = eig.eigenvectors().col(0).normalized();
  for (int i = 0; i < count; ++i) {
    if (std::abs(fit.direction.dot(points[i] - fit.anchor)) > tolerance) return fit;
  }
  fit.normals.row(0) = fit.direction.transpose();
  fit.rows = 1;
  fit.valid = true;
  return fit;
}

void residualAndJacobian(const FeatureFit& fit, const Eigen::Isometry3d& T_world_lidar,
                         const Eigen::Vector3d& p_lidar, Eigen::Vector2d& r, Eigen::Matrix<double, 2, 6>& J) {
  const Eigen::Matrix3d& R = T_world_lidar.linear();
  const Eigen::Vector3d p_world = R * p_lidar + T_world_lidar.translation();
  r = fit.normals * (p_world - fit.anchor);
  J.leftCols<3>() = fit.normals * R;
  J.rightCols<3>() = -fit.normals * R * geometry::hat(p_lidar);
}

}  // namespace drover::lidar::detail
