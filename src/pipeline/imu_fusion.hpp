#pragma once
// The IMU side of the LIS (LIO-SAM's imuPreintegration node): static initialisation of attitude and gyro bias,
// high-rate propagation for deskewing and initial guesses, and the fixed-lag smoother that fuses each sweep's
// lidar pose with the preintegrated IMU to estimate velocity and biases. Failure of the smoother (implausible
// velocity or bias) resets it at the lidar pose, as LIO-SAM's failureDetection does.
#include <Eigen/Geometry>
#include <limits>
#include <optional>
#include <string>

#include "backend/fixed_lag_smoother.hpp"
#include "imu/initializer.hpp"
#include "imu/propagator.hpp"
#include "lidar/deskew.hpp"
#include "pipeline/odometry_config.hpp"
#include "pipeline/path_odometer.hpp"
#include "pipeline/static_hold.hpp"
#include "pipeline/visual_motion.hpp"
#include "types/imu.hpp"
#include "types/trajectory.hpp"

namespace drover::pipeline {

struct ScanOutcome;

class ImuFusion {
 public:
  // T_imu_lidar: the lidar's pose on the IMU (body).
  ImuFusion(const OdometryConfig& config, const Eigen::Isometry3d& T_imu_lidar);

  // Checks and buffers one sample; the status says whether it was accepted (and after a gap) or dropped.
  imu::SampleStatus addImu(const ImuSample& sample);
  // True when sweeps should wait for IMU data: the IMU is enabled, has produced samples and was not given up.
  bool wantsImu() const;
  Time latestImuTime() const { return propagator_.latestTime(); }
  // The IMU time a sweep [t0, t_end] needs before it is processed: its end, and for the very first sweep also
  // the initialisation window after t0.
  Time coverageNeeded(Time t0, Time t_end, bool first_sweep) const;

  // At the first sweep (t0 [ns]): initialises attitude and gyro bias from the IMU window and starts the smoother
  // and the propagation there. Gives the IMU up (lidar only, with a note) when that is impossible.
  void tryInitialize(Time t0, bool first_sweep);
  bool initialized() const { return initialized_; }
  const std::string& initNote() const { return init_note_; }

  std::optional<lidar::SweepMotion> sweepMotion(Time t0, Time t_end) const;
  std::optional<Eigen::Isometry3d> predictLidarPose(Time t) const;
  // The IMU's pose T_world_imu at t, propagated from the newest fused state through the buffered samples (LIO-SAM's
  // IMU-rate odometry); nullopt before initialisation or outside the propagated range.
  std::optional<Eigen::Isometry3d> propagatedImuPose(Time t) const;
  // Pose of the first sweep: gravity-aligned from the IMU attitude when initialised, else the identity.
  Eigen::Isometry3d initialLidarPose() const;

  // Fuses the sweep's matched pose (out.T_world_lidar at out.t) with the IMU since the previous sweep; sets
  // out.reset / out.warning on a smoother failure, and replaces a failed match's pose by the fused one. With
  // config.gravity_roll_pitch the sweep's roll and pitch become the smoother's: its IMU factors see gravity, while
  // scan matching lets tilt drift (LIO-SAM blends the IMU's roll/pitch into the mapping pose for the same reason).
  void update(ScanOutcome& out, const Trajectory& trajectory);

  // Moves the smoother and the propagation into a corrected world frame after a loop closure: the smoother
  // restarts at T_new_old * T_world_imu with its velocity rotated and its biases kept (as LIO-SAM re-initialises
  // its IMU graph on the corrected odometry), and the gyro bias keeps the certainty the old window had of it; the
  // accelerometer bias too when the correction turns the world about gravity only (a 4-DoF pose graph).
  void reanchor(const Eigen::Isometry3d& T_new_old);

  // The VIS's newest state after a camera frame (time order): its motion between sweeps then enters update() as a
  // relative-pose factor and visualLidarGuess() as the matcher's guess, while config.vis_fusion allows and the VIS
  // is healthy (pipeline/visual_motion.hpp).
  void addVisualState(const VisualState& state) { visual_.add(state); }
  // LVI-SAM's updateInitialGuess: the lidar pose at t as the pose of the sweep `previous` (T_world_lidar) moved by
  // the VIS's motion between the two stamps; nullopt with `why` when the VIS cannot give it or the option is off.
  std::optional<Eigen::Isometry3d> visualLidarGuess(Time t, const StampedPose& previous, std::string* why) const;

  imu::ImuStreamStats imuStats() const { return propagator_.stats(); }
  // The smoother's newest fused state and bias (what the IMU-rate propagation starts from); nullopt before the
  // smoother runs. The live system re-anchors its own IMU-rate propagation on it after every sweep.
  std::optional<imu::FusedState> fusedState() const;

 private:
  // Smoother and propagation from `state`, under the config's first-state prior; the gyro bias's under the given
  // covariance [(rad/s)^2] when there is one, or both biases' under `bias_covariance` [gyro; acc].
  void restart(const imu::NavState& state, const imu::ImuBias& bias,
               const std::optional<Eigen::Matrix3d>& gyro_bias_covariance = std::nullopt,
               const std::optional<Eigen::Matrix<double, 6, 6>>& bias_covariance = std::nullopt);
  // `disagreed` (optional) is set when a VIS increment existed but the gates refused it.
  std::optional<VisualIncrement> checkedVisualIncrement(Time a, Time b, std::string* why,
                                                        bool* disagreed = nullptr) const;
  // Counts the sweeps after initialising down; at the config's sweep restarts the smoother with the lidar's velocity
  // when the start was moving (true then).
  bool restartAfterMovingStart(ScanOutcome& out, const Eigen::Isometry3d& T_world_imu_measured,
                               const Trajectory& trajectory);
  Eigen::Matrix<double, 6, 6> poseSqrtInformation(const ScanOutcome& out, const Eigen::Isometry3d& T_world_imu,
                                                  bool aided) const;
  std::optional<Eigen::Matrix<double, 6, 6>> biasCovarianceAfter(double gap) const;
  bool holdAtRest(const std::vector<ImuSample>& samples, Time a, Time b);
  Eigen::Matrix<double, 6, 6> zeroMotionSqrtInformation() const;

  OdometryConfig config_;
  Eigen::Isometry3d T_imu_lidar_, T_lidar_imu_;
  imu::ImuPropagator propagator_;
  imu::StaticInitializer initializer_;
  backend::FixedLagSmoother smoother_;
  VisualMotion visual_;
  VisualWatch visual_watch_;
  PathOdometer odometer_;  // the fused states' path, for the VIS's keyframe gate
  // [ns] the newest sweep at which the smoother's velocity was measured (a match constraining all six directions,
  // the VO factor, the static hold) or restarted: the VIS's velocity gate widens with the time since
  Time velocity_measured_at_ = 0;
  StaticHold hold_;        // a static start held at rest until the IMU says it moved (config.static_hold)
  bool initialized_ = false, given_up_ = false;
  Time t_start_ = 0;                  // [ns] the first sweep's stamp
  // Sweeps left until the moving-start check (> 0), then its retries (<= 0); kDone when judged or disabled.
  static constexpr int kDone = std::numeric_limits<int>::min();
  int sweeps_to_moving_restart_ = kDone;
  bool static_start_ = false;
  imu::ImuBias start_bias_;
  std::string init_note_ = "no IMU data";
  Eigen::Isometry3d T_world_imu0_ = Eigen::Isometry3d::Identity();
};

}  // namespace drover::pipeline
