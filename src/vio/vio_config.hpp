#pragma once
// Configuration of the visual-inertial odometry (the VIS): a VINS-Mono sliding window (Qin, Li, Shen, "VINS-Mono",
// T-RO 2018, Sec. V-VI) with LVI-SAM's lidar depth (Shan et al., ICRA 2021, Sec. III-B). Units in the comments.
#include <string>

namespace drover::vio {

// How the lidar depth of a feature enters the window (LVI-SAM holds it fixed).
enum class DepthMode {
  kFixed,   // the feature's inverse depth is set from the lidar and held constant (LVI-SAM)
  kFactor,  // an inverse-depth factor with a sigma that grows with the association's spread and the depth
  kOff,     // lidar depth is not used (monocular triangulation only)
};
const char* toString(DepthMode mode);

// How the window is initialised.
enum class InitMode {
  kAuto,    // from the LIS when it runs and is initialised, else visual-inertial alignment
  kLis,     // only from the LIS (waits for it)
  kVisual,  // only by visual-inertial alignment (VINS-Mono Sec. V), even when a lidar runs
};
const char* toString(InitMode mode);

struct VioConfig {
  int window = 10;                 // keyframes in the window; the newest frame comes on top (VINS WINDOW_SIZE)
  double min_parallax_px = 10;     // [px at focal_px] average parallax that makes a keyframe (VINS MIN_PARALLAX)
  int min_tracked_for_parallax = 20;  // fewer features tracked from the previous frame: a keyframe (VINS: 20)
  double focal_px = 460;           // [px] virtual focal length of the parallax test (VINS FOCAL_LENGTH)
  // Once initialised, a frame this long after the newest keyframe is a keyframe whatever its parallax (0: never, as
  // VINS-Mono). Without it a window that sees only far features makes no keyframe while the robot drives on, and
  // the newest frame hangs off the last keyframe by one preintegration over the whole gap, whose position sigma
  // grows as t^1.5: on the white walls' 30 s the window then held still for seconds and jumped (see
  // pipeline/visual_motion.hpp).
  double max_keyframe_interval_s = 0;  // [s]
  double sigma_px = 1.5;           // [px] reprojection sigma at the camera's own focal length (VINS: 1.5 px)
  double robust_px = 1.5;          // [px] Cauchy loss scale on the reprojection error (VINS: Cauchy(1) whitened)
  double outlier_px = 3.0;         // [px] observations with a larger error after the solve are dropped
  int min_observations = 2;        // a feature is used when seen in this many frames of the window (VINS: 2)
  int max_features = 200;          // features in the solve (the longest tracks first)
  DepthMode depth_mode = DepthMode::kFixed;
  double depth_sigma_m = 0.02;     // [m] factor mode: sigma of a lidar depth at 1 m with no spread ...
  double depth_sigma_rel = 0.01;   // ... plus this fraction of the depth (the association's median error is 0.4 %) ...
  double depth_sigma_spread = 0.2; // ... plus this fraction of the 3 lidar neighbours' range spread [m]
  int max_iterations = 5;          // Ceres iterations per frame (VINS NUM_ITERATIONS: 8 under a 40 ms limit)
  double max_solver_ms = 40;       // [ms] solver time limit per frame; only in live use (replay is deterministic)
  bool estimate_extrinsic = false; // refine T_imu_cam online (VINS ESTIMATE_EXTRINSIC 1)
  bool estimate_time_offset = true;  // estimate the camera-IMU time offset td (VINS ESTIMATE_TD)
  double time_offset_sigma_s = 0.005;  // [s] prior on td around the calibration's offset
  double max_time_offset_s = 0.05; // [s] |td| above this is a failure
  bool imu_midpoint = true;         // integrate the IMU by the mid-point rule (VINS-Mono) instead of holding samples
  InitMode init = InitMode::kAuto;
  // Per frame, the covariance of the newest pose relative to the previous frame from the window's information
  // (FrameResult::relative_covariance; the LIS weights the VIS's motion by it with vis_fusion.window_covariance,
  // which needs this on too). Off by default: it costs ~2.5x the window's solve (farm course: 47 against 18 ms a
  // frame on a loaded 2-core machine).
  bool relative_covariance = false;
  // The prior on the oldest frame at initialisation (sigmas): from the LIS, and from visual-inertial alignment.
  double init_sigma_position_m = 0.01;   // [m] (holds the gauge)
  double lis_sigma_rotation_rad = 0.01;  // [rad]
  double lis_sigma_velocity = 0.5;       // [m/s] (weak: the seed is a finite difference; a tight one fixes its error)
  double lis_sigma_gyro_bias = 0.005;    // [rad/s]
  double lis_sigma_acc_bias = 0.1;       // [m/s^2]
  // While the LIS runs, its biases (fused over many lidar-matched sweeps) as a prior on the newest frame's biases
  // at every solve, with these sigmas; never marginalised, so it does not pile up. It holds the tilt /
  // accelerometer-bias pair that a straight drive leaves unobservable to the window. 0: off.
  double lis_bias_prior_sigma_gyro = 0;  // [rad/s]
  double lis_bias_prior_sigma_acc = 0;   // [m/s^2]
  // Without a LIS, the accelerometer's turn-on bias (1 sigma per axis, from the IMU's datasheet) as a prior toward
  // zero on the newest frame's accelerometer bias at every solve, never marginalised. At constant velocity the
  // window cannot tell a bias along an axis from a tilt of gravity (b = g x tilt: 0.17 m/s^2 per degree), so without
  // it the pair wanders wherever the tracks' noise pushes it, and a tilted body makes the path climb or dive. 0: off.
  double acc_bias_prior_sigma = 0;  // [m/s^2]
  // A seed is refused when the window's lidar-anchored tracks, moved by the LIS's poses, reproject to a median
  // error above seed_max_median_px [px at focal_px] over at least seed_min_observations observations (sliding
  // tracks on a textureless surface, or a LIS whose velocity drifted; vio/seed_agreement.hpp). 0 disables.
  double seed_max_median_px = 3.0;
  int seed_min_observations = 30;
  double align_sigma_rotation_rad = 0.03;  // [rad]
  double align_sigma_velocity = 0.5;       // [m/s]
  double align_sigma_gyro_bias = 0.01;     // [rad/s]
  double align_sigma_acc_bias = 0.3;       // [m/s^2]
  // Visual-inertial alignment (no lidar): VINS-Mono's thresholds.
  double init_min_parallax_px = 30;     // [px at focal_px] relative-pose pair
  double init_min_acc_excitation = 0.25;  // [m/s^2] std of the window's average accelerations
  // The alignment's scale must be known to this relative standard error (from its residuals); the velocity prior
  // at initialisation then widens to align_sigma_velocity (+) this error times the speed.
  double init_max_scale_rel_sigma = 0.1;
  // After a visual-inertial initialisation (no LIS), the window's scale and tilt are checked against the IMU over
  // the last scale_check_span_s of keyframes, every scale_check_every_s (vio/scale_check.hpp), and corrected when
  // determined to scale_check_max_rel_sigma (1 sigma) and off by more than max(scale_check_min_change, 2 sigma). A
  // factor beyond [1 / scale_check_max_change, scale_check_max_change] is a failure. The sigma is the residuals' (+)
  // scale_check_bias_sigma over the span's acceleration std: a car braking and turning (0.5-2 m/s^2 on
  // kitti05-replay) passes, a walking-pace robot (0.01-0.2 m/s^2 on the farm's courses) does not. kitti05-replay, the
  // VIS alone: 26.8 m APE with the check, 310 m without; the farm's 24 course runs: no correction, the same drifts
  // (bench/RESULTS.md). span 0: no check.
  double scale_check_span_s = 15;       // [s]
  double scale_check_every_s = 5;       // [s]
  double scale_check_max_rel_sigma = 0.03;
  double scale_check_min_change = 0.02;
  double scale_check_max_change = 2.0;
  double scale_check_bias_sigma = 0.01;  // [m/s^2] the accelerometer bias error the check does not estimate
  // A ground robot's height as the scale a constant-speed drive does not give the IMU (backend/ground_factor.hpp):
  // a feature without lidar depth whose point, as last solved, lies within ground_gate_rel times the camera's height
  // above the surface below the anchor frame's body (the height error a scale error of that fraction makes) and
  // within ground_max_range_m of it (horizontally) is held to that surface with sigma
  // sqrt(ground_sigma_m^2 + (ground_slope_sigma_rad * range)^2) under a Cauchy loss at one sigma. 0 height: off
  // (a hand-held rig or a drone has no such surface). Only while no LIS state seeds the window: beside the LIS the
  // lidar gives the scale, and on the farm course the ground factors there took the lvi-sam preset's APE from 0.35 to
  // 2.35 m (bench/RESULTS.md).
  double ground_height_m = 0;            // [m] IMU origin above the surface driven on, along the body z axis
  double ground_sigma_m = 0.03;          // [m] the surface's roughness and the body's bounce on it
  double ground_slope_sigma_rad = 0.02;  // [rad] the surface's slope under a feature relative to the body's plane
  double ground_gate_rel = 0.2;          // [1] of the camera's height above the surface
  double ground_max_range_m = 8;         // [m]
  // The ground as a check of the scale (window_ground_check.cpp), while the ground factors are on: every
  // ground_check_every_s, each point of the window below the camera and within ground_max_range_m implies a scale if
  // it lies on the ground (its depth below the camera over the camera's height; scales within
  // [1 / scale_check_max_change, scale_check_max_change] are considered). When at least
  // ground_check_min_points of them agree within +-ground_check_cluster_rel, outnumber twice the points inside the
  // ground factors' gate, and put the scale off by more than ground_gate_rel at two checks in a row (the second within
  // ground_check_cluster_rel of the first), the window is rescaled by it. A window whose scale left the gate
  // (coasting through a dark stretch on the IMU, whose forward bias a constant-speed drive hides) is out of the
  // ground factors' reach; this brings it back. 0: off.
  double ground_check_every_s = 1;         // [s]
  int ground_check_min_points = 10;
  double ground_check_cluster_rel = 0.1;  // [1] half-width of the agreeing scales
  // Failure detection (VINS-Mono failureDetection).
  int min_tracked = 8;             // fewer features tracked into the newest frame: failure (with a LIS to seed it
                                   // again; alone, after coast_max_s)
  double coast_max_s = 30;         // [s] alone, a window with too few tracks goes on on the IMU this long (0: never)
  double max_acc_bias = 2.5;       // [m/s^2]
  double max_gyro_bias = 1.0;      // [rad/s]
  double max_jump_m = 5.0;         // [m] position change between consecutive frames
  double max_height_jump_m = 1.0;  // [m] z change between consecutive frames
  double max_turn_deg = 50.0;      // [deg] rotation between consecutive frames
  double max_speed = 50.0;         // [m/s]
  double max_imu_gap_s = 0.1;      // [s] a longer stretch without IMU samples between frames clears the window
  std::string validate() const;    // empty = valid, else names the bad value
};

}  // namespace drover::vio
