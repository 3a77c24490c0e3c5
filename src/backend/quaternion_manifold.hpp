#pragma once
// The rotation parameter block of every backend factor: a unit quaternion stored in Eigen's coefficient order
// (x, y, z, w), perturbed on the RIGHT as in Forster et al. (TRO 2017, Eq. 5 and Sec. VI):
//   Plus(q, dtheta) = q (x) Exp(dtheta),   Minus(y, x) = Log(x^-1 (x) y),
// so the tangent vector dtheta [rad] is a rotation in the BODY frame (R -> R Exp(dtheta)). This differs from
// ceres::EigenQuaternionManifold, which perturbs on the left (Exp(dtheta) (x) q, world frame).
//
// The factors give their analytic Jacobians in the tangent space (d r / d dtheta) and hand Ceres the matching
// ambient 4-column Jacobian  J_ambient = J_tangent * 4 P(q)^T,  P = d Plus / d dtheta at 0. Because every factor
// normalises q before use, its residual is invariant to the scale of q, and 4 P P^T = I - q q^T is the projector
// onto the sphere's tangent space, so this J_ambient is the exact derivative in R^4 (not a convention) and
// J_ambient * P = J_tangent exactly.
#include <ceres/manifold.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace drover::backend {

using Matrix43d = Eigen::Matrix<double, 4, 3>;
using Matrix34d = Eigen::Matrix<double, 3, 4>;

// P(q) = d (q (x) Exp(dtheta)) / d dtheta at dtheta = 0, rows in Eigen's (x, y, z, w) order; q must be unit.
Matrix43d quaternionPlusJacobian(const Eigen::Quaterniond& q);

// Ambient (4-column) Jacobian from a tangent (3-column) one at unit q: J_tangent * 4 P(q)^T.
template <int Rows>
Eigen::Matrix<double, Rows, 4> ambientFromTangent(const Eigen::Matrix<double, Rows, 3>& J_tangent,
                                                  const Eigen::Quaterniond& q) {
  return J_tangent * (4.0 * quaternionPlusJacobian(q).transpose());
}

class RightQuaternionManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 4; }
  int TangentSize() const override { return 3; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

// A rotation that may only turn about the WORLD z axis (gravity's, in a gravity-aligned world): one tangent
// coordinate, the yaw increment dpsi [rad],
//   Plus(q, dpsi) = Exp(dpsi e_z) (x) q,   Minus(y, x) = the yaw of y (x) x^-1,
// so the angle between the body axes and the vertical (roll and pitch) never changes. VINS-Mono's 4-DoF pose graph
// (Qin et al., T-RO 2018, Sec. VIII-B): with an IMU, roll and pitch are observable from gravity (once turns have
// told a tilt from an accelerometer bias), so a loop closure corrects x, y, z and yaw only. Same (x, y, z, w) storage as RightQuaternionManifold, and the
// factors' ambient Jacobians (exact in R^4, see above) serve both.
class WorldYawManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 4; }
  int TangentSize() const override { return 1; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace drover::backend
