#pragma once
// Ceres factors of the sliding-window visual-inertial estimator: the reprojection of an inverse-depth feature with
// online camera-IMU time offset (VINS-Mono, Qin et al., T-RO 2018, Sec. VI-B; the time-offset model of Qin & Shen,
// "Online temporal calibration for camera-IMU systems", IROS 2018 -- VINS-Mono's ProjectionTdFactor), and a lidar
// depth prior on that inverse depth.
// Parameter blocks follow the other backend factors: p [m] (3), q (4, Eigen (x, y, z, w) order,
// RightQuaternionManifold: R -> R Exp(dtheta)); plus inverse depth lambda [1/m] (1) and time offset td [s] (1).
// Backend-internal header (included by backend .cpp files and tests only).
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace drover::backend {

// A feature first seen (anchored) in frame i at inverse depth lambda along the anchor camera's z axis, observed
// again in frame j. Blocks: p_world_imu_i, q_world_imu_i, p_world_imu_j, q_world_imu_j, p_imu_cam, q_imu_cam
// (extrinsic T_imu_cam), inverse_depth lambda [1/m] (in anchor camera i), td [s] (t_imu = t_cam + td).
// With the observations shifted to the frames' state times at constant image velocity (Qin & Shen 2018),
//   n_k = [obs_k - (td - td_k) velocity_k; 1],  k = i, j,
//   P_ci = n_i / lambda,  P_w = R_wi (R_ic P_ci + p_ic) + p_wi,  P_cj = R_ic^T (R_wj^T (P_w - p_wj) - p_ic),
//   r = sqrt_information (P_cj.xy / P_cj.z - n_j.xy)   (2, the normalised-plane error scaled to sigmas).
class ReprojectionFactor final : public ceres::SizedCostFunction<2, 3, 4, 3, 4, 3, 4, 1, 1> {
 public:
  // obs_*: undistorted normalised coordinates (x/z, y/z) in frames i and j; velocity_* [1/s]: the feature's
  // velocity on the normalised plane in that frame; td_i, td_j [s]: the td each frame's state time was computed
  // with; sqrt_information = focal_px / sigma_px [1] (isotropic). Throws std::invalid_argument for non-finite
  // inputs or sqrt_information <= 0.
  ReprojectionFactor(const Eigen::Vector2d& obs_i, const Eigen::Vector2d& obs_j, const Eigen::Vector2d& velocity_i,
                     const Eigen::Vector2d& velocity_j, double td_i, double td_j, double sqrt_information);

  // False (Ceres rejects the step) only when lambda = 0, |P_cj.z| <= 1e-9 m or a value is not finite. A point
  // behind a camera (lambda < 0 or P_cj.z < 0) evaluates to a large finite residual, as in VINS-Mono.
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  // P_cj.z [m], the feature's depth in the observing camera j at these parameters (> 0: in front).
  double cheirality(double const* const* parameters) const;

 private:
  Eigen::Vector2d obs_i_, obs_j_, velocity_i_, velocity_j_;
  double td_i_, td_j_, sqrt_information_;
};

// A lidar depth d [m] (along the anchor camera's z) with standard deviation sigma_d [m] as a prior on the inverse
// depth: r = (lambda - 1/d) / (sigma_d / d^2), the denominator the first-order sigma of 1/d. Block: lambda (1).
class InverseDepthFactor final : public ceres::SizedCostFunction<1, 1> {
 public:
  // Throws std::invalid_argument when depth or sigma_depth is not finite and > 0.
  InverseDepthFactor(double depth, double sigma_depth);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  double inverse_depth_;  // 1/d [1/m]
  double weight_;         // d^2 / sigma_d [m]
};

}  // namespace drover::backend
