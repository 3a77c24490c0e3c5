#pragma once
// Visual-inertial initialisation (Qin, Li, Shen, "VINS-Mono", T-RO 2018, Sec. V; its initial_aligment.cpp):
// a vision-only SfM of a short window (vio/initial_sfm.hpp) is aligned with the IMU preintegrations to recover
// the gyroscope bias (Sec. V-B-1), the velocities, the gravity vector and the metric scale (Sec. V-B-2, linear),
// gravity refined on its sphere |g| = G (Sec. V-B-3), and finally the world frame is rotated so gravity is
// (0, 0, -G) (Sec. V-B-4). The accelerometer bias is taken as zero, as in VINS-Mono.
//
// Differences to VINS-Mono: the preintegration is Drover's (Forster, imu/preintegration.hpp, gravity as an
// acceleration vector pointing down) so the linear system's signs differ from the paper's Eq. 10-11; the
// gyroscope bias uses the Forster Jacobian dR/dbg (Log of the rotation error instead of 2 vec(q)); the
// excitation check refuses (VINS-Mono only prints); a rotation-only window is refused in the SfM; the linear
// system is solved for 1 / scale (AlignmentConfig::inverse_scale), and a window whose scale its residuals leave
// uncertain is refused (max_scale_rel_sigma).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "imu/preintegration.hpp"
#include "types/imu.hpp"
#include "types/time.hpp"
#include "vio/initial_sfm.hpp"

namespace drover::vio {

struct InitFrame {
  Time t = 0;               // [ns] camera stamp, already in IMU time
  FrameFeatures features;   // feature id -> undistorted normalised coordinates in this frame
  std::vector<ImuSample> imu;  // raw samples from the previous frame's t to this t (empty for the first frame)
};

struct AlignmentConfig {
  SfmConfig sfm;                     // focal_px, min_parallax_px, min_correspondences, ... (vio/initial_sfm.hpp)
  double min_acc_excitation = 0.25;  // [m/s^2] std over the window of the frame-to-frame average acceleration
                                     // dv/dt; below it: not enough motion (VINS-Mono: 0.25)
  double max_gravity_error = 1.0;    // [m/s^2] allowed ||g_est| - G| after the linear alignment (VINS-Mono: 1.0)
  double min_scale = 1e-3;           // metric / visual scale, at or below it: refused. The SfM's l <-> last
                                     // baseline has unit length, so this is that baseline in metres.
  // The scale's relative standard error (LinearAlignment::scale_sigma / scale) above which the window is refused.
  // On simulated courses the error of the accepted scale was within 1-2x this sigma.
  double max_scale_rel_sigma = 0.1;
  // true: each IMU interval is integrated with the mean of its two end samples (VINS-Mono's mid-point rule,
  // right for samples of the instantaneous rate); false: each sample is held until the next (Drover's
  // imu::Preintegrator::integrateRange). At 200 Hz and 2-3 rad/s^2 of angular acceleration, holding instantaneous
  // samples biases the gyroscope-bias estimate by ~4e-3 rad/s (measured in tests/vio/test_initial_alignment.cpp).
  bool imu_midpoint = true;
  // true: the linear alignment solves for 1 / scale with the SfM positions on the right-hand side, so that their
  // noise does not shrink the scale (errors in the regressors attenuate a least-squares slope towards zero: the
  // direct form underestimated the speed on every window of a simulated car, by 0.6x at 10 m/s).
  bool inverse_scale = true;
  int gyro_bias_iterations = 2;      // re-linearisations of the gyroscope-bias least squares (VINS-Mono: 1)
  int refine_gravity_iterations = 4; // VINS-Mono RefineGravity: 4
  // Empty when valid.
  std::string validate() const;
};

struct AlignmentResult {
  bool ok = false;
  std::string why;  // one line naming the failed step, with the measured value vs the threshold
  // Per frame, world gravity-aligned: gravity (0, 0, -G), z up; yaw of the IMU of frame 0 = 0, its position 0.
  std::vector<Eigen::Isometry3d> T_world_imu;
  std::vector<Eigen::Vector3d> v_world;                        // [m/s] IMU velocity in the world
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();         // [rad/s]
  double scale = 0;                                            // metric / visual (diagnostic)
  Eigen::Vector3d gravity_camera_l = Eigen::Vector3d::Zero();  // [m/s^2] gravity in camera l (diagnostic)
  std::map<std::uint64_t, Eigen::Vector3d> points_world;       // triangulated features, metric, world frame
  int l = -1;                                                  // SfM reference frame (diagnostic)
  double acc_excitation = 0;                                   // [m/s^2] measured std of dv/dt (diagnostic)
  double scale_rel_sigma = 0;  // the scale's relative standard error (LinearAlignment::scale_sigma / scale)
};

// The whole initialisation. Throws std::invalid_argument when a config is invalid; every other failure is
// ok = false with `why`.
AlignmentResult alignVisualInertial(const std::vector<InitFrame>& frames, const Eigen::Isometry3d& T_imu_cam,
                                    const imu::PreintegrationConfig& imu_config, const AlignmentConfig& config);

// ---- The steps, exposed for tests. ----

// Preintegrations between consecutive frames (element k: frame k -> k+1) at `bias`. All samples of the window
// are merged (equal stamps once) and integrated by imu::Preintegrator::integrateRange, each held until the next;
// with `midpoint` each sample is first replaced by the mean of it and the next one. The first sample is held back
// to the first frame's stamp when it comes later. Throws std::invalid_argument when the window has no IMU sample.
std::vector<imu::Preintegrator> preintegrateWindow(const std::vector<InitFrame>& frames, const imu::ImuBias& bias,
                                                   const imu::PreintegrationConfig& imu_config, bool midpoint);

// Standard deviation [m/s^2] of dv_k / dt_k over the window (VINS-Mono initialStructure's excitation check).
double accelerationExcitation(const std::vector<imu::Preintegrator>& preintegrations);
// The root-mean-square distance of the vectors from their mean (their spread; 0 for fewer than two).
double spreadAboutMean(const std::vector<Eigen::Vector3d>& values);

// Gyroscope-bias correction (VINS-Mono solveGyroscopeBias, Eq. 9 with Forster's first-order correction): the
// least-squares dbg minimising sum |Log(dR_k^T R_bk^T R_bk+1) - dR/dbg_k dbg|^2, R_bk the SfM IMU rotations.
Eigen::Vector3d solveGyroscopeBias(const std::vector<Eigen::Matrix3d>& R_l_imu,
                                   const std::vector<imu::Preintegrator>& preintegrations);

// Velocities (each in its own IMU frame), gravity in c_l and scale from the SfM (VINS-Mono LinearAlignment and
// RefineGravity). p_l_cam: SfM camera positions in c_l (visual scale), R_l_imu: SfM IMU rotations.
struct LinearAlignment {
  std::vector<Eigen::Vector3d> v_imu;  // [m/s], v_k in IMU frame k
  Eigen::Vector3d g_l = Eigen::Vector3d::Zero();  // [m/s^2] gravity acceleration in c_l (points down)
  double scale = 0;
  // The scale's standard error from the residuals: sigma^2 = |r|^2 / (rows - unknowns) times the scale's entry of
  // (A^T A)^-1. Large where the window cannot tell a forward acceleration from a gravity tilt (no rotation, a
  // steady acceleration). refineGravity only; infinity when the system is singular or has no redundancy.
  double scale_sigma = 0;
};
LinearAlignment linearAlignment(const std::vector<Eigen::Matrix3d>& R_l_imu, const std::vector<Eigen::Vector3d>& p_l_cam,
                                const Eigen::Vector3d& p_imu_cam, const std::vector<imu::Preintegrator>& preintegrations,
                                bool inverse_scale = true);
// Same with |g| = G: g = G normalised(g0) + B w over a 2-d tangent basis B, re-linearised `iterations` times.
LinearAlignment refineGravity(const std::vector<Eigen::Matrix3d>& R_l_imu, const std::vector<Eigen::Vector3d>& p_l_cam,
                              const Eigen::Vector3d& p_imu_cam, const std::vector<imu::Preintegrator>& preintegrations,
                              const Eigen::Vector3d& g0, double gravity, int iterations, bool inverse_scale = true);

}  // namespace drover::vio
