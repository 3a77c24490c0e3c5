#pragma once
// The VIS's motion as the LIS uses it (LVI-SAM, Shan et al. ICRA 2021, Sec. III-B-1 and III-C): the VIS publishes
// its newest state at every camera frame, and the LIS asks for the VIS's motion between two sweep stamps -- the
// scan matcher's initial guess (LVI-SAM's updateInitialGuess) and a relative-pose factor in the LIS's IMU smoother
// (the paper's visual odometry factor, which LVI-SAM's released code leaves out). The VIS pose at a sweep stamp is
// its newest published state at or before the stamp, carried to it by the IMU with that state's velocity and
// biases (a camera frame is at most 1/rate before it). Increments are differences of published poses, so chained
// over a run they telescope to the VIS's own trajectory: the fusion adds no drift of its own.
// A VIS state is used only while the VIS is healthy: initialised for `warmup`, enough features in its solve, the
// same reset ID (LVI-SAM's) at both ends, and a state no older than `max_age` at the stamp (a camera blackout).
#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>

#include "imu/preintegration.hpp"
#include "imu/propagator.hpp"
#include "types/time.hpp"
#include "vio/sliding_window.hpp"

namespace drover::pipeline {

struct VisualMotionConfig {
  bool factor = true;          // the VIS's motion as a relative-pose factor in the LIS's IMU smoother
  bool initial_guess = true;   // the VIS's motion as the scan matcher's initial guess (else the IMU's)
  // The guess too only after a degenerate sweep (the matcher keeps a degenerate match's directions at its guess, so
  // there the VIS's motion carries them), the IMU's where the previous match constrained all six directions: there
  // the IMU's prediction from the smoother's state is the better start, and a match is not quite independent of
  // where it starts. On kitti05-replay (never degenerate) the VIS's guess on every sweep cost 0.156 -> 0.160 m of
  // APE with the drover preset; the farm's seeds 1-4 went 0.236 / 0.219 / 0.222 / 0.135 -> 0.224 / 0.180 / 0.224 /
  // 0.203 m, within one seed's spread (bench/RESULTS.md). false: LVI-SAM's updateInitialGuess, on every sweep.
  bool initial_guess_degenerate_only = true;
  // The factor only on sweeps whose match is degenerate: where the lidar constrains all six directions its pose
  // (to the map, ~1 cm) is better than the VIS's motion (2 cm + 5 %), whose errors are correlated from sweep to
  // sweep (one window) and pull the estimate off. On kitti05-replay (never degenerate, up to 14 m/s) the factor on
  // every sweep cost 0.149 -> 0.188 m of APE, all of it in height; on the farm course this rule costs 0.156 ->
  // 0.175 m (seed 1; bench/RESULTS.md). false: a factor on every sweep.
  bool factor_degenerate_only = true;
  // The factor's sigmas over one sweep interval, in the earlier sweep's IMU frame: a floor plus a share of the
  // motion (the VIS's own drift is 0.3-1.6 % of its path on the simulated courses, its per-frame jitter ~1 cm).
  double sigma_position = 0.02;        // [m]
  double sigma_position_ratio = 0.05;  // [m per m moved]
  double sigma_rotation = 0.01;        // [rad]
  double sigma_rotation_ratio = 0.05;  // [rad per rad turned]
  // Instead of the sigmas above: the VIS window's own covariance of its motion (the per-frame relative-pose
  // covariances of vio.relative_covariance, summed over the frames between the two states) plus these floors for
  // what the window's linearisation leaves out (the IMU carry from the frames to the sweep stamps). Needs
  // vio.relative_covariance: without it the drift model above is used. Farm course, no loops: 0.23 % against 0.28 %
  // with the drift model, the difference within reruns; corridor 0.30 % against 0.41-0.60 %.
  bool window_covariance = false;
  double window_floor_position = 0.005;  // [m]
  double window_floor_rotation = 0.002;  // [rad]
  int min_features = 20;    // [-] a VIS state with fewer features in its solve is not used
  int full_features = 80;   // [-] below this many the sigmas grow as sqrt(full_features / features)
  double warmup = 1.0;      // [s] after the VIS (re)initialises its states are not used for this long
  double max_age = 0.2;     // [s] the newest VIS state before a sweep stamp must be at most this old
  // A VIS that lost its features can stall: on the farm's white walls it made no keyframe for 35 s (its window
  // kept the old ones), held still for 3 s while the robot drove 2.7 m on, then jumped 3 m back to the truth.
  // While the LIS's IMU prediction says the robot moves faster than `standing_speed`, a VIS whose last keyframe is
  // older than `max_keyframe_gap`, or came more than that after the one before, is not used (standing still, no
  // keyframe is due): a lone keyframe in a stall re-enabled it for 0.5 s, which took the LIS from 0.88 to 0.42 m/s.
  // Gating on the LIS's own velocity instead caught the stall only after it had dragged that velocity down, then
  // locked the recovered VIS out. Gross disagreement with the IMU prediction of the sweep interval (the catch-up
  // jump, a collapsed scale) is refused too.
  double max_keyframe_gap = 0.5;          // [s] (a moving VIS makes 7-10 keyframes a second)
  double standing_speed = 0.2;            // [m/s]
  // ... and the LIS moved at least this far since that keyframe (or between it and the one before): a VIS whose last
  // keyframe was taken standing has none due until it has moved. Pulling away at 0.4 m/s^2 after a stand, the time
  // gap alone refused the VIS for 0.3-0.5 s (its first moving keyframe, 0.16 m on, came 1.3 s after the standing
  // one); a moving VIS keyframes every 8-11 cm at 0.8 m/s, and the white walls' stall drove 2.7 m. 0: time alone.
  double keyframe_gap_min_distance = 0.25;  // [m]
  // ... and, when this is > 0, the VIS's velocity is more than this (plus max_velocity_difference_ratio times the
  // predicted speed) off the IMU's prediction: a stall is a VIS that lost its translation. Leaving the farm's white
  // walls (seed 1, 2x2 frames) the drover preset's VIS ran at 0.94-1.00 m/s at a true 1.00, on 13-19 tracks with
  // lidar depth, but made no keyframe by parallax for up to 2.8 s (far walls ahead): refused for it, it was reset
  // twice while the blind LIS slowed from 0.87 to 0.73 m/s. On the white-walls course the gap came with a VIS at
  // 0.30-0.54 m/s (scale collapsed) against the LIS's 0.98. 0 (the default): every gap while moving is a stall. A VIS
  // that coasts without seeing its translation agrees with the IMU's prediction too, and the velocity alone cannot
  // tell it: with the platform file's SuperPoint tracks (no keyframes by time, the lower LK threshold) the corridor's
  // textureless stretch left 26-35 tracks sliding on the wall and a window of 150 stale features, and that VIS,
  // slowing from 0.99 to 0.79 m/s within 0.02 m/s of the LIS, took the LIS with it (0.78 -> 2.60 % drift). The drover
  // preset sets 0.2 (apps/drover/run_preset.cpp): its LK threshold drops those tracks and the VIS resets instead.
  double keyframe_gap_velocity_tolerance = 0;  // [m/s]
  // The VIS's velocity at the later stamp (body frame) within max_velocity_difference, plus _ratio times the
  // IMU-predicted speed (the VIS's scale error), plus _growth times the time since the LIS's velocity was last
  // measured (a match constraining all six directions, the VO factor or the static hold): what the IMU alone may
  // have carried it off by since, at an accelerometer bias error of _growth. A healthy VIS differed from the LIS's
  // prediction, at the sweeps it was used, by at most 0.037 m/s on the corridor's seeds 1-3 and 0.21 m/s on
  // kitti05-replay (at 10.9 m/s, the lvi-sam preset's ungated VIS); leaving the farm's 22 s of white walls (seed 1,
  // 2x2 frames) the LIS was 0.28-0.38 m/s slow and the VIS right. On the white-walls course SuperPoint's VIS, down to
  // 20 wall tracks, collapsed its scale to a third (0.33 m/s at a true 1.00 m/s, 0.5 s after the lidar last held the
  // LIS) and passed the former flat 1.0 m/s gate on 6 sweeps, slowing the blind LIS by 6 mm/s (4 cm of APE) before
  // the acceleration gate caught it; weighted by the window's own covariance, as confident on 20 tracks, one such
  // sweep cost 1.4 m. A flat 0.2 m/s + 5 % locked the farm's right VIS out after the white walls (0.155 -> 0.316 m):
  // re-initialised from the slow LIS, it corrected its own speed and was refused again. bench/RESULTS.md.
  double max_velocity_difference = 0.2;          // [m/s]
  double max_velocity_difference_ratio = 0.05;   // [m/s per m/s of the predicted speed]
  // [m/s per s unmeasured] the simulated IMU's turn-on bias is 0.02-0.03 m/s^2; the white-walls course's LIS held
  // 0.041 against a true 0.020 (its tilt taking the rest); the farm's white walls cost 0.013 m/s^2 on average.
  double max_velocity_difference_growth = 0.05;
  double max_position_difference = 0.5;   // [m] translation between the stamps
  // The gates above compare one sweep interval with the IMU's prediction from the LIS's newest state, which the VIS
  // itself has pulled: a VIS that slowly runs away drags that state along and passes them. The VIS's and the LIS's
  // attitudes and accelerometer biases each explain the same specific force; the body-frame acceleration they make
  // of it differs by (R_vis^T g - R_lis^T g) - (b_vis - b_lis): the rate at which the VIS's velocity leaves the
  // LIS's. A tilt that its bias offsets (straight driving leaves the pair unobservable) cancels out of it. With
  // SuperPoint, the corridor's VIS re-initialised after a textureless stretch tilted itself 0.77 deg within 1.2 s
  // with its bias within 0.01 m/s^2 of the LIS's: 0.22 m/s^2, and it ran from 0.97 to 1.4 m/s in 2.6 s at a steady
  // 1.0 m/s, the LIS with it (20 % drift over the course). Healthy VIS: at most 0.045 m/s^2 on the short courses,
  // 0.054 m/s^2 over the farm (bench/RESULTS.md).
  double max_acceleration_difference = 0.08;  // [m/s^2]
  // A VIS the gates above refused for this long in a row is asked to reset (it then re-initialises from the LIS):
  // on a textureless stretch of the corridor it stalled, was refused for 5 s, and re-joined 4 m behind. 0: never.
  double reset_after = 1.5;               // [s]
  // Empty when valid: sigmas and ratios finite (sigmas > 0, ratios >= 0), 0 < min_features <= full_features,
  // warmup >= 0, max_age > 0, reset_after >= 0, max_acceleration_difference > 0.
  std::string validate() const;
};

// The VIS's newest state after one camera frame (VisualOdometry's FrameResult), in the VIS's world frame.
struct VisualState {
  Time t = 0;                                                     // [ns] IMU time of the frame
  Eigen::Isometry3d T_world_imu = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();              // [m/s]
  imu::ImuBias bias;
  int features = 0;           // features in the frame's solve
  std::uint32_t reset_id = 0; // the VIS's (re)initialisation count: states of different IDs are not related
  Time initialized_at = 0;    // [ns] when the VIS last (re)initialised
  // [ns] the VIS's newest keyframe made by parallax (its initialisation when none since); keyframes made by
  // vio.max_keyframe_interval_s alone do not count: they keep a stalled window conditioned, not moving.
  Time last_keyframe_at = 0;
  Time keyframe_interval = 0; // [ns] from the keyframe before it (0 when none)
  // Of the pose relative to the previous frame's state (vio::FrameResult::relative_covariance), when computed.
  std::optional<Eigen::Matrix<double, 6, 6>> relative_covariance;
};

// The VIS's per-frame results as VisualStates, its (re)initialisations numbered (LVI-SAM's reset ID). Shared by
// the replay (apps/drover/run_vis.cpp) and the live system.
class VisualStateStream {
 public:
  // The state after this frame, or nothing when the VIS has no estimate at it.
  std::optional<VisualState> onFrame(const vio::FrameResult& r);

 private:
  std::uint32_t init_count_ = 0;
  Time init_time_ = 0, keyframe_time_ = 0, keyframe_interval_ = 0;
};

// The VIS's motion T_a_b = T_world_imu(a)^-1 T_world_imu(b) with the square-root information of its error
// [dp in frame a (m); dtheta (rad)], as backend::RelativePoseMeasurement takes it.
struct VisualIncrement {
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> sqrt_information = Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::Vector3d v_b = Eigen::Vector3d::Zero();  // [m/s] the VIS's velocity at b in the IMU frame at b
  Time last_keyframe_at = 0;                      // [ns] of the VIS state used at b
  Time keyframe_interval = 0;                     // [ns] of the VIS state used at b
  Eigen::Vector3d gravity_b = Eigen::Vector3d::Zero();   // [m/s^2] world gravity in the IMU frame at b, by the VIS
  Eigen::Vector3d acc_bias_b = Eigen::Vector3d::Zero();  // [m/s^2] the VIS's accelerometer bias at b
};

// How far the LIS moved [m] since the VIS's last keyframe (to b) and between that keyframe and the one before it;
// unknown (infinite) leaves the keyframe gate to time alone.
struct KeyframeTravel {
  double since_keyframe = std::numeric_limits<double>::infinity();
  double keyframe_interval = std::numeric_limits<double>::infinity();
};

// Empty when the increment agrees with the IMU's prediction of the same interval (states at a and b, world frame
// of their own) within config.max_velocity_difference (plus _ratio times the predicted speed, plus _growth times
// `unmeasured_s`, the seconds since the LIS's velocity was last measured) and max_position_difference, and the VIS
// made a keyframe within max_keyframe_gap of b (and the one before within that of it) unless the prediction stands
// still, the LIS moved less than keyframe_gap_min_distance over the gap, or the VIS's velocity is within
// keyframe_gap_velocity_tolerance (plus the ratio) of the prediction; else why not.
std::string disagreementWithImu(const VisualIncrement& inc, const imu::NavState& a, const imu::NavState& b,
                                const VisualMotionConfig& config, const KeyframeTravel& travel = {},
                                double unmeasured_s = 0);

// Empty when the body-frame acceleration the VIS makes of the IMU's specific force at b (its attitude and bias,
// inc.gravity_b and inc.acc_bias_b) is within config.max_acceleration_difference of the LIS's (its state b, gravity
// `gravity` [m/s^2], accelerometer bias `lis_acc_bias`); else why not.
std::string accelerationDisagreement(const VisualIncrement& inc, const imu::NavState& b, double gravity,
                                     const Eigen::Vector3d& lis_acc_bias, const VisualMotionConfig& config);

class VisualMotion {
 public:
  // Throws std::invalid_argument when config.validate() fails.
  VisualMotion(const VisualMotionConfig& config, const imu::PreintegrationConfig& imu);

  // States in time order; one not after the newest is ignored. Keeps the last kKept seconds.
  void add(const VisualState& state);
  // The VIS's motion between stamps a < b, carried by the buffered IMU samples of `imu`; nullopt with `why` set
  // when the VIS cannot give it (no state, unhealthy, a reset between, no IMU cover).
  std::optional<VisualIncrement> increment(Time a, Time b, const imu::ImuPropagator& imu, std::string* why) const;
  const VisualMotionConfig& config() const { return config_; }
  bool empty() const { return states_.empty(); }

  static constexpr Time kKept = 5'000'000'000;  // [ns]

 private:
  // The VIS's state at t: the newest usable state at or before t, propagated to t.
  std::optional<imu::NavState> stateAt(Time t, const imu::ImuPropagator& imu, const VisualState** used,
                                      std::string* why) const;
  // The window's covariance of the motion from state a to state b (nothing when a state between lacks one).
  std::optional<Eigen::Matrix<double, 6, 6>> windowCovariance(const VisualState* a, const VisualState* b) const;
  VisualMotionConfig config_;
  imu::PreintegrationConfig imu_;
  std::deque<VisualState> states_;
};

// The LIS's half of "the failing side resets and re-joins" (LVI-SAM re-initialises a failed VIS from the LIS):
// a VIS that runs and is past its warm-up, but which the gates of disagreementWithImu refuse at every sweep for
// reset_after seconds, is asked to reset once; the count starts again after it.
class VisualWatch {
 public:
  explicit VisualWatch(double reset_after_s) : reset_after_(fromSeconds(reset_after_s)) {}
  // One sweep at t: the VIS was used, or refused by a gate (`refused` says why), or had no usable state (neither).
  // Returns why the VIS should reset, once the refusals have lasted reset_after; else empty.
  std::string onSweep(Time t, bool used, const std::string& refused);

 private:
  Time reset_after_;
  std::optional<Time> since_;
};

}  // namespace drover::pipeline
