#pragma once
// Fixed-lag smoother of the IMU navigation state, after LIO-SAM's imuPreintegration graph (Shan et al., IROS
// 2020, Sec. III-B), solved with Ceres. The window holds the last `window` states x_k = (T_world_imu, v_world,
// [b_g; b_a]); consecutive states are linked by the preintegrated IMU factor (Forster et al., TRO 2017, Eq. 45)
// and the bias random walk, and each new state gets a pose prior from lidar odometry. When the window overflows,
// the oldest state is marginalised by a proper Schur complement (see backend/marginalization.hpp) into a linear
// prior on the new oldest state, so no information is dropped or double counted.
// Rotations are perturbed on the right, R -> R Exp(dtheta) (backend/quaternion_manifold.hpp).
// This header is free of Ceres (pimpl).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>

#include "imu/preintegration.hpp"
#include "types/time.hpp"

namespace drover::backend {

struct FixedLagSmootherConfig {
  int window = 10;                      // [states] kept in the window, >= 2
  // Defaults of the lidar odometry pose measurement (update() without an explicit information).
  double lidar_sigma_position = 0.05;   // [m]
  double lidar_sigma_rotation = 0.01;   // [rad]
  // Prior on the first state (initialize()).
  double prior_sigma_position = 0.01;   // [m]
  double prior_sigma_rotation = 0.01;   // [rad]
  double prior_sigma_velocity = 1.0;    // [m/s]
  double prior_sigma_gyro_bias = 0.01;  // [rad/s]
  double prior_sigma_acc_bias = 0.1;    // [m/s^2]
  // Floor on the bias random-walk densities of the IMU config, so a zero random walk does not pin the biases
  // with an infinite weight.
  double min_gyro_bias_random_walk = 1e-6;  // [rad/s^2/sqrt(Hz)]
  double min_acc_bias_random_walk = 1e-5;   // [m/s^3/sqrt(Hz)]
  int max_iterations = 10;              // Levenberg-Marquardt iterations per update, >= 1
  // Failure detection as LIO-SAM's failureDetection(): the newest state is implausible.
  double max_velocity = 30.0;           // [m/s], |v_world| above -> failure
  double max_bias = 1.0;                // |b_g| [rad/s] or |b_a| [m/s^2] above -> failure
  // Empty when valid: window >= 2, max_iterations >= 1, every sigma and threshold finite and > 0.
  std::string validate() const;
};

// A relative pose measurement between the newest state i and the state update() adds, j (visual odometry:
// the VIS's motion between two sweeps): T_i_j = T_world_imu_i^-1 T_world_imu_j, whitened by the 6x6 square-root
// information of the error [dp in frame i (m); dtheta (rad, right perturbation)] (RelativePoseFactor).
struct RelativePoseMeasurement {
  Eigen::Isometry3d T_i_j = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> sqrt_information = Eigen::Matrix<double, 6, 6>::Identity();
};

struct SmootherUpdate {
  bool ok = false;        // solved, finite and plausible; the window moved on
  bool failure = false;   // the solution was implausible or not finite: the caller should reset()
  std::string reason;     // why not ok (names the offending value)
  int iterations = 0;     // solver iterations of this update
  double initial_cost = 0, final_cost = 0;  // Ceres cost 0.5 |r|^2 before and after
  int states = 0;         // states in the window after the update
  imu::NavState state;    // newest state; on failure the last good one (never NaN)
  imu::ImuBias bias;      // its bias; on failure the last good one
};

class FixedLagSmoother {
 public:
  using Config = FixedLagSmootherConfig;
  // Throws std::invalid_argument when config.validate() fails.
  explicit FixedLagSmoother(const Config& config = Config());
  ~FixedLagSmoother();
  FixedLagSmoother(FixedLagSmoother&&) noexcept;
  FixedLagSmoother& operator=(FixedLagSmoother&&) noexcept;

  // Starts a window with one state under the config's prior. Throws std::invalid_argument for a non-finite
  // state/bias or an invalid IMU config (whose bias random walks and gravity the smoother uses).
  void initialize(const imu::NavState& state, const imu::ImuBias& bias, const imu::PreintegrationConfig& imu);
  // The same, with the gyro bias prior's covariance [(rad/s)^2] given instead of the config's sigma: a restart
  // that keeps what an earlier window knew of the gyro bias (gyroBiasCovariance()). Throws std::invalid_argument
  // also when the covariance is not finite, symmetric and positive definite.
  void initialize(const imu::NavState& state, const imu::ImuBias& bias, const imu::PreintegrationConfig& imu,
                  const Eigen::Matrix3d& gyro_bias_covariance);
  // A start known to be at rest: the first state's velocity prior becomes N(state.v_world, sigma^2 I) [m/s] instead of
  // the config's prior_sigma_velocity (a start whose velocity is unknown). Only on a fresh window (one state, no
  // update yet): throws std::logic_error otherwise, std::invalid_argument for a sigma that is not finite and > 0.
  void setFirstVelocitySigma(double sigma);
  // The newest state's gyro bias marginal covariance [(rad/s)^2] given everything in the window (the inverse of
  // the window's Gauss-Newton information at the current estimate; bit-identical for equal windows wherever their
  // states lie in memory). Nothing when not initialized or when the covariance cannot be computed.
  std::optional<Eigen::Matrix3d> gyroBiasCovariance() const;
  // The same for both biases, [gyro (rad/s); acc (m/s^2)] (6x6), and a restart with that prior on both: for a
  // restart after a correction that turned the world about gravity only, which changes neither bias.
  std::optional<Eigen::Matrix<double, 6, 6>> biasCovariance() const;
  void initialize(const imu::NavState& state, const imu::ImuBias& bias, const imu::PreintegrationConfig& imu,
                  const Eigen::Matrix<double, 6, 6>& bias_covariance);

  // Adds state j at t_j = state().t + fromSeconds(pim.deltaTime()) (the time predict() gives), linked to the
  // newest state by the IMU factor of `pim` (integrated from state().t, at any linearisation bias) and the bias
  // random walk, with the pose measurement T_world_imu_measured whitened by `pose_sqrt_information` -- a 6x6
  // square-root information L (L^T L = Sigma^-1) of the error [dp_world (m); dtheta (rad, right perturbation)].
  // Initial values from pim.predict(); solves; slides the window. Never throws on a failed solve (reports
  // failure, and rolls the window back to before the call); throws std::invalid_argument when not initialized,
  // pim.deltaTime() <= 0, the pim's covariance is not positive definite, or the inputs are not finite.
  // With `relative`, also that relative pose between the newest state and the new one (it enters the
  // marginalisation like the IMU factor when the newest state leaves the window).
  SmootherUpdate update(const imu::Preintegrator& pim, const Eigen::Isometry3d& T_world_imu_measured,
                        const Eigen::Matrix<double, 6, 6>& pose_sqrt_information,
                        const std::optional<RelativePoseMeasurement>& relative = std::nullopt);
  // The same with the config's lidar_sigma_position / lidar_sigma_rotation.
  SmootherUpdate update(const imu::Preintegrator& pim, const Eigen::Isometry3d& T_world_imu_measured);

  imu::NavState state() const;  // newest state (throws std::logic_error when not initialized)
  imu::ImuBias bias() const;    // its bias
  bool initialized() const;
  int size() const;             // states in the window
  void reset();                 // back to not initialized (keeps the config)
  const Config& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drover::backend
