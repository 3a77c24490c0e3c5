#pragma once
// A ground robot's known height above the surface it drives on, as a prior on the depth of a feature that lies on
// that surface: the metric scale a monocular window cannot get from its IMU while the robot drives at constant
// speed (Wu et al., "VINS on Wheels", ICRA 2017, Sec. IV: under constant acceleration the scale is unobservable),
// taken from the ground as monocular car odometry does (Song & Chandraker, "Robust scale estimation in real-time
// monocular SFM for autonomous driving", CVPR 2014). Blocks as in visual_factors.hpp. Backend-internal header.
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace drover::backend {

// A feature anchored in camera i at inverse depth lambda [1/m] along its ray n = (obs, 1), believed to lie on the
// ground: its height in the anchor IMU frame, z of P_b = R_ic n / lambda + p_ic, is -height [m] (the IMU origin
// `height` above the surface, the body's z axis normal to it), with standard deviation sigma [m]:
//   r = (e_z^T (R_ic n / lambda + p_ic) + height) / sigma.
// Blocks: p_imu_cam (3), q_imu_cam (4), inverse_depth (1).
class GroundHeightFactor final : public ceres::SizedCostFunction<1, 3, 4, 1> {
 public:
  // Throws std::invalid_argument for a non-finite obs, height <= 0 or sigma <= 0.
  GroundHeightFactor(const Eigen::Vector2d& obs, double height_m, double sigma_m);
  // False only for lambda = 0 or a non-finite value.
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Eigen::Vector3d ray_;
  double height_, weight_;
};

}  // namespace drover::backend
