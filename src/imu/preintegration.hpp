#pragma once
// On-manifold IMU preintegration (Forster, Carlone, Dellaert, Scaramuzza, "On-Manifold Preintegration for
// Real-Time Visual-Inertial Odometry", TRO 2017). Between keyframes i and j the measurements are summarised as
//   dR_ij = prod Exp((w_k - bg_hat) dt)                                   (Eq. 33)
//   dv_ij = sum dR_ik (a_k - ba_hat) dt
//   dp_ij = sum [dv_ik dt + 1/2 dR_ik (a_k - ba_hat) dt^2]
// with first-order bias corrections (Eq. 44), the 9x9 covariance of [dphi, dv, dp] propagated as in Eq. 62-63,
// and the prediction of state j from state i (Eq. 38 rearranged):
//   R_j = R_i dR_ij,  v_j = v_i + g dt_ij + R_i dv_ij,  p_j = p_i + v_i dt_ij + 1/2 g dt_ij^2 + R_i dp_ij.
// All vectors of the IMU sample are in the IMU (body) frame; world frame is z up with gravity (0, 0, -g).
// The residual ordering used everywhere in Drover is [rotation, velocity, position] = [phi, v, p] (each 3).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "types/imu.hpp"
#include "types/time.hpp"

namespace drover::imu {

using Matrix9d = Eigen::Matrix<double, 9, 9>;
using Vector9d = Eigen::Matrix<double, 9, 1>;

// Gyroscope and accelerometer biases, IMU frame.
struct ImuBias {
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();  // [rad/s]
  Eigen::Vector3d acc = Eigen::Vector3d::Zero();   // [m/s^2]
};

// The navigation state of the IMU (body) frame.
struct NavState {
  Time t = 0;                                                     // [ns]
  Eigen::Isometry3d T_world_imu = Eigen::Isometry3d::Identity();  // pose of the IMU in the world
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();              // [m/s], velocity of the IMU in the world
};

// An estimator's newest state with the bias it was estimated with (what a propagation starts from).
struct FusedState {
  NavState state;
  ImuBias bias;
};

// Noise model of the IMU (continuous-time densities, Kalibr convention; names as LIO-SAM's imuAccNoise etc.).
struct PreintegrationConfig {
  double gyro_noise_density = 1.7e-4;   // [rad/s/sqrt(Hz)]
  double acc_noise_density = 2.0e-3;    // [m/s^2/sqrt(Hz)]
  double gyro_bias_random_walk = 2.0e-5;  // [rad/s^2/sqrt(Hz)]
  double acc_bias_random_walk = 3.0e-4;   // [m/s^3/sqrt(Hz)]
  double integration_sigma = 1e-4;       // [m/s^2/sqrt(Hz)] position-integration noise (GTSAM's integrationCov)
  double gravity = 9.81;                 // [m/s^2], world gravity is (0, 0, -gravity)
  // Empty when valid: every value finite and >= 0, gravity > 0.
  std::string validate() const;
};

class Preintegrator {
 public:
  // Starts an empty preintegration (identity deltas, zero covariance) at the linearisation bias `bias_hat`.
  // Throws std::invalid_argument when config.validate() fails.
  Preintegrator(const ImuBias& bias_hat, const PreintegrationConfig& config);

  // Adds one measurement held constant for dt [s] (dt > 0 and finite, else std::invalid_argument).
  void integrate(const Eigen::Vector3d& omega_imu, const Eigen::Vector3d& acc_imu, double dt);
  // Integrates the samples of [t0, t1] (ns): each sample's value is held from its stamp until the next one;
  // the first sample at or before t0 and the samples up to t1 are used. Samples must be time-ordered and
  // cover t0 (a sample at or before t0); throws std::invalid_argument otherwise (or for t1 < t0). The partial
  // first and last intervals are cut at t0 and t1 exactly; when the samples end before t1 the last one is held
  // until t1. Splitting a range at a sample time gives the same deltas as one call; splitting it elsewhere
  // differs at O(dt^2) (the discrete update holds dR_ik over each step).
  void integrateRange(const std::vector<ImuSample>& samples, Time t0, Time t1);

  // Clears the deltas (keeps the config) and sets a new linearisation bias.
  void reset(const ImuBias& bias_hat);

  double deltaTime() const { return dt_; }                  // [s], sum of integrated dt
  const Eigen::Matrix3d& deltaR() const { return dR_; }     // dR_ij at bias_hat
  const Eigen::Vector3d& deltaV() const { return dV_; }     // [m/s]
  const Eigen::Vector3d& deltaP() const { return dP_; }     // [m]
  const ImuBias& biasHat() const { return bias_hat_; }
  const Matrix9d& covariance() const { return cov_; }      // of [dphi, dv, dp]
  // Jacobians of the deltas w.r.t. the biases at bias_hat (Forster Appendix B).
  const Eigen::Matrix3d& dR_dbg() const { return dR_dbg_; }
  const Eigen::Matrix3d& dV_dbg() const { return dV_dbg_; }
  const Eigen::Matrix3d& dV_dba() const { return dV_dba_; }
  const Eigen::Matrix3d& dP_dbg() const { return dP_dbg_; }
  const Eigen::Matrix3d& dP_dba() const { return dP_dba_; }

  // Deltas corrected to first order for a bias different from bias_hat (Eq. 44).
  Eigen::Matrix3d correctedDeltaR(const ImuBias& bias) const;
  Eigen::Vector3d correctedDeltaV(const ImuBias& bias) const;
  Eigen::Vector3d correctedDeltaP(const ImuBias& bias) const;

  // State j predicted from state i with the (corrected) deltas; result.t = state_i.t + deltaTime().
  NavState predict(const NavState& state_i, const ImuBias& bias) const;

  // The 9-vector residual [r_phi, r_v, r_p] of Forster Eq. 45 between states i and j with bias `bias`:
  //   r_phi = Log(corrected dR^T R_i^T R_j), r_v = R_i^T (v_j - v_i - g dt) - corrected dv,
  //   r_p = R_i^T (p_j - p_i - v_i dt - 1/2 g dt^2) - corrected dp.
  Vector9d residual(const NavState& state_i, const NavState& state_j, const ImuBias& bias) const;

  const PreintegrationConfig& config() const { return config_; }
  Eigen::Vector3d gravityWorld() const { return Eigen::Vector3d(0, 0, -config_.gravity); }

 private:
  PreintegrationConfig config_;
  ImuBias bias_hat_;
  double dt_ = 0;
  Eigen::Matrix3d dR_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d dV_ = Eigen::Vector3d::Zero(), dP_ = Eigen::Vector3d::Zero();
  Matrix9d cov_ = Matrix9d::Zero();
  Eigen::Matrix3d dR_dbg_ = Eigen::Matrix3d::Zero(), dV_dbg_ = Eigen::Matrix3d::Zero(),
                  dV_dba_ = Eigen::Matrix3d::Zero(), dP_dbg_ = Eigen::Matrix3d::Zero(),
                  dP_dba_ = Eigen::Matrix3d::Zero();
};

}  // namespace drover::imu
