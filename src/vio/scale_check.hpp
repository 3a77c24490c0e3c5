#pragma once
// The VIS's metric scale and tilt checked against the IMU over a long stretch of its own keyframes (the idea of
// ORB-SLAM3's scale refinement, Campos et al., T-RO 2021, Sec. V-B: re-estimate scale and gravity once the map
// spans more motion than the initialisation's window). The estimated trajectory takes the place of the
// structure from motion in the visual-inertial alignment (vio/initial_alignment.hpp, inverse-scale form): its
// camera positions and rotations, up to a scale s and a tilt of gravity, must explain the preintegrated IMU.
//
// Why: a monocular window initialised at a wrong scale keeps it while the motion does not reveal it (a car at a
// steady speed), and its marginal prior holds it; at the next brake or bend the IMU disagrees with the visual
// tracks and the window drops the tracks as outliers instead of rescaling. Over 15 s of a drive the scale is
// determined to +-0.2-1.7 % (kitti05-replay, 1 sigma) where the initialisation's second saw +-6-10 %.
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "imu/preintegration.hpp"
#include "types/imu.hpp"
#include "types/time.hpp"

namespace drover::vio {

// One keyframe of the estimated trajectory and the IMU samples that lead to it from the previous one.
struct ScaleCheckFrame {
  Time t = 0;                                                    // [ns] IMU time
  Eigen::Isometry3d T_world_imu = Eigen::Isometry3d::Identity(); // the VIS's estimate
  imu::ImuBias bias;                                             // its bias estimate (integration point)
  std::vector<ImuSample> imu;  // samples covering [previous frame's t, t], the last at or before the previous t
                               // first (empty for the first frame)
};

struct ScaleCheck {
  bool ok = false;
  std::string why;                 // when not ok: which step failed, with its numbers
  double scale = 1;                // metric / estimated: multiply the VIS's distances and speeds by it
  double rel_sigma = 0;            // relative standard error of scale (from the residuals, white noise)
  double acc_std = 0;              // [m/s^2] std of the world-frame acceleration over the keyframe intervals: the
                                   // signal the scale is measured by (an unmodelled accelerometer bias error b
                                   // rotating with the body errs the scale by up to b / acc_std, which the
                                   // residuals do not show)
  Eigen::Matrix3d R_fix = Eigen::Matrix3d::Identity();  // rotates the estimated world so gravity is -z
  double tilt_rad = 0;             // angle of R_fix [rad]
  std::vector<Eigen::Vector3d> v_world;  // [m/s] per frame, corrected world frame
};

// Gravity's magnitude from imu_config. Fewer than 3 frames: ok = false. Throws std::invalid_argument when a frame's
// IMU does not cover its interval.
ScaleCheck checkScale(const std::vector<ScaleCheckFrame>& frames, const Eigen::Isometry3d& T_imu_cam,
                      const imu::PreintegrationConfig& imu_config);

}  // namespace drover::vio
