#pragma once
// Private helper of ScanMatcher (included by its .cpp and by its tests, by no other module): the map features a
// scan point is matched to and the residual with its analytic Jacobian.
//
// A feature is an anchor a (world) and 1 or 2 unit normals stacked in N (rows): a plane has its normal (1 row);
// a line with direction u has two unit vectors spanning the plane orthogonal to u (2 rows). The residual of the
// lidar point p at pose T = (R, t) is
//   r(T) = N (R p + t - a),   |r| = point-to-plane or point-to-line distance [m].
// LIO-SAM uses the scalar distance for lines; its gradient is undefined at zero distance, the 2-vector is smooth.
// Jacobian for the right perturbation T Exp(dxi), dxi = [rho; phi] in the lidar frame (se3.hpp ordering):
//   R Exp(phi) p + R rho + t ~= R p + t + R rho - R [p]x phi,   so   dr/ddxi = N [R, -R [p]x].
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace drover::lidar::detail {

struct FeatureFit {
  bool valid = false;
  int rows = 0;                                                   // 2 for a line, 1 for a plane
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();               // [m] world: the neighbours' mean
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();            // line direction or plane normal (unit)
  Eigen::Matrix<double, 2, 3> normals = Eigen::Matrix<double, 2, 3>::Zero();  // first `rows` rows used
};

// LIO-SAM's line test: the neighbours' covariance has a largest eigenvalue > eigen_ratio x the second; the line
// runs through their mean along the principal eigenvector.
FeatureFit fitLine(const Eigen::Vector3d* points, int count, double eigen_ratio);
// Plane through the neighbours' mean with the smallest-eigenvalue eigenvector as normal (PCA; LIO-SAM solves
// A n = -1, which fails for planes through the origin). Valid when every neighbour lies within `tolerance` [m]
// of the plane, the neighbours are not collinear, and their spread across their longest direction is at least
// `min_aspect` of their spread along it (ScanMatcherConfig::plane_min_aspect).
FeatureFit fitPlane(const Eigen::Vector3d* points, int count, double tolerance, double min_aspect = 0.0);

// r (first fit.rows entries) at T_world_lidar for the lidar point p_lidar; J the matching rows of dr/ddxi.
void residualAndJacobian(const FeatureFit& fit, const Eigen::Isometry3d& T_world_lidar,
                         const Eigen::Vector3d& p_lidar, Eigen::Vector2d& r, Eigen::Matrix<double, 2, 6>& J);

}  // namespace drover::lidar::detail
