#include "imu/preintegration.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "geometry/so3.hpp"

namespace drover::imu {

namespace {

using geometry::expSO3;
using geometry::hat;

void checkNonNegative(std::ostringstream& out, const char* name, double value) {
  if (!std::isfinite(value) || value < 0) out << name << " = " << value << " must be finite and >= 0; ";
}

// The stored delta rotation is a product of hundreds of rotations: re-project it through a unit quaternion so
// that rounding never accumulates into a non-orthonormal matrix.
Eigen::Matrix3d renormalized(const Eigen::Matrix3d& R) {
  return Eigen::Quaterniond(R).normalized().toRotationMatrix();
}

}  // namespace

std::string PreintegrationConfig::validate() const {
  std::ostringstream out;
  checkNonNegative(out, "gyro_noise_density", gyro_noise_density);
  checkNonNegative(out, "acc_noise_density", acc_noise_density);
  checkNonNegative(out, "gyro_bias_random_walk", gyro_bias_random_walk);
  checkNonNegative(out, "acc_bias_random_walk", acc_bias_random_walk);
  checkNonNegative(out, "integration_sigma", integration_sigma);
  if (!std::isfinite(gravity) || gravity <= 0) out << "gravity = " << gravity << " must be finite and > 0; ";
  return out.str();
}

Preintegrator::Preintegrator(const ImuBias& bias_hat, const PreintegrationConfig& config) : config_(config) {
  const std::string error = config.validate();
  if (!error.empty()) throw std::invalid_argument("PreintegrationConfig: " + error);
  reset(bias_hat);
}

void Preintegrator::reset(const ImuBias& bias_hat) {
  if (!bias_hat.gyro.allFinite() || !bias_hat.acc.allFinite()) {
    throw std::invalid_argument("Preintegrator: bias_hat is not finite");
  }
  bias_hat_ = bias_hat;
  dt_ = 0;
  dR_.setIdentity();
  dV_.setZero();
  dP_.setZero();
  cov_.setZero();
  dR_dbg_.setZero();
  dV_dbg_.setZero();
  dV_dba_.setZero();
  dP_dbg_.setZero();
  dP_dba_.setZero();
}

void Preintegrator::integrate(const Eigen::Vector3d& omega_imu, const Eigen::Vector3d& acc_imu, double dt) {
  if (!std::isfinite(dt) || dt <= 0) {
    throw std::invalid_argument("Preintegrator::integrate: dt = " + std::to_string(dt) + " must be finite and > 0");
  }
  if (!omega_imu.allFinite() || !acc_imu.allFinite()) {
    throw std::invalid_argument("Preintegrator::integrate: measurement is not finite");
  }
  const Eigen::Vector3d w = omega_imu - bias_hat_.gyro;  // bias-corrected rate [rad/s], IMU frame
  const Eigen::Vector3d f = acc_imu - bias_hat_.acc;     // bias-corrected specific force [m/s^2]
  const Eigen::Matrix3d dRk = expSO3(w * dt);            // Exp((w_k - bg) dt)
  const Eigen::Matrix3d Jr = geometry::rightJacobianSO3(w * dt);
  const Eigen::Matrix3d dR_f_hat = dR_ * hat(f);  // dR_ik [a_k - ba]_x
  const double dt2 = dt * dt;

  // Noise propagation (Forster Eq. 62-63) with A, B, C evaluated at dR_ik (before the update):
  //   eta_{k+1} = A eta_k + B n_g + C n_a, eta = [dphi, dv, dp].
  Matrix9d A = Matrix9d::Identity();
  A.block<3, 3>(0, 0) = dRk.transpose();
  A.block<3, 3>(3, 0) = -dR_f_hat * dt;
  A.block<3, 3>(6, 0) = -0.5 * dR_f_hat * dt2;
  A.block<3, 3>(6, 3) = Eigen::Matrix3d::Identity() * dt;
  Eigen::Matrix<double, 9, 3> B = Eigen::Matrix<double, 9, 3>::Zero(), C = Eigen::Matrix<double, 9, 3>::Zero();
  B.block<3, 3>(0, 0) = Jr * dt;
  C.block<3, 3>(3, 0) = dR_ * dt;
  C.block<3, 3>(6, 0) = 0.5 * dR_ * dt2;
  // Discrete white noise from the continuous densities: Cov(n_d) = sigma^2 / dt.
  const double qg = config_.gyro_noise_density * config_.gyro_noise_density / dt;
  const double qa = config_.acc_noise_density * config_.acc_noise_density / dt;
  cov_ = A * cov_ * A.transpose() + qg * B * B.transpose() + qa * C * C.transpose();
  // Position-integration noise, as GTSAM's integrationCovariance: sigma_int^2 dt on the position block.
  cov_.block<3, 3>(6, 6) += Eigen::Matrix3d::Identity() * (config_.integration_sigma * config_.integration_sigma * dt);

  // Bias Jacobians (Forster Appendix B), position and velocity first since they use dR_ik and d(dR_ik)/dbg.
  dP_dba_ += dV_dba_ * dt - 0.5 * dR_ * dt2;
  dP_dbg_ += dV_dbg_ * dt - 0.5 * dR_f_hat * dR_dbg_ * dt2;
  dV_dba_ -= dR_ * dt;
  dV_dbg_ -= dR_f_hat * dR_dbg_ * dt;
  dR_dbg_ = dRk.transpose() * dR_dbg_ - Jr * dt;

  // Deltas (Forster Eq. 33 in iterative form), again position first.
  const Eigen::Vector3d dR_f = dR_ * f;
  dP_ += dV_ * dt + 0.5 * dR_f * dt2;
  dV_ += dR_f * dt;
  dR_ = renormalized(dR_ * dRk);
  dt_ += dt;
}

void Preintegrator::integrateRange(const std::vector<ImuSample>& samples, Time t0, Time t1) {
  if (t1 < t0) {
    throw std::invalid_argument("Preintegrator::integrateRange: t1 = " + std::to_string(t1) + " < t0 = " +
                                std::to_string(t0));
  }
  for (std::size_t k = 1; k < samples.size(); ++k) {
    if (samples[k].t < samples[k - 1].t) {
      throw std::invalid_argument("Preintegrator::integrateRange: samples not time-ordered at index " +
                                  std::to_string(k) + " (t = " + std::to_string(samples[k].t) + ")");
    }
  }
  // The last sample at or before t0 holds over t0 (zero-order hold).
  const auto after_t0 = std::upper_bound(samples.begin(), samples.end(), t0,
                                         [](Time t, const ImuSample& s) { return t < s.t; });
  if (after_t0 == samples.begin()) {
    throw std::invalid_argument("Preintegrator::integrateRange: no sample at or before t0 = " + std::to_string(t0));
  }
  for (auto it = after_t0 - 1; it != samples.end(); ++it) {
    const Time begin = std::max(it->t, t0);
    if (begin >= t1) break;
    // The last sample is held until t1 when the samples end before it.
    const Time end = (it + 1 == samples.end()) ? t1 : std::min((it + 1)->t, t1);
    if (end > begin) integrate(it->omega_imu, it->acc_imu, toSeconds(end - begin));
  }
}

Eigen::Matrix3d Preintegrator::correctedDeltaR(const ImuBias& bias) const {
  // Eq. 44: dR(bg) = dR(bg_hat) Exp(dR/dbg dbg).
  return dR_ * expSO3(dR_dbg_ * (bias.gyro - bias_hat_.gyro));
}

Eigen::Vector3d Preintegrator::correctedDeltaV(const ImuBias& bias) const {
  return dV_ + dV_dbg_ * (bias.gyro - bias_hat_.gyro) + dV_dba_ * (bias.acc - bias_hat_.acc);
}

Eigen::Vector3d Preintegrator::correctedDeltaP(const ImuBias& bias) const {
  return dP_ + dP_dbg_ * (bias.gyro - bias_hat_.gyro) + dP_dba_ * (bias.acc - bias_hat_.acc);
}

NavState Preintegrator::predict(const NavState& state_i, const ImuBias& bias) const {
  const Eigen::Matrix3d R_i = state_i.T_world_imu.linear();
  const Eigen::Vector3d p_i = state_i.T_world_imu.translation();
  const Eigen::Vector3d g = gravityWorld();
  NavState state_j;
  state_j.t = state_i.t + fromSeconds(dt_);
  state_j.T_world_imu.linear() = renormalized(R_i * correctedDeltaR(bias));
  state_j.T_world_imu.translation() = p_i + state_i.v_world * dt_ + 0.5 * g * dt_ * dt_ + R_i * correctedDeltaP(bias);
  state_j.v_world = state_i.v_world + g * dt_ + R_i * correctedDeltaV(bias);
  return state_j;
}

Vector9d Preintegrator::residual(const NavState& state_i, const NavState& state_j, const ImuBias& bias) const {
  const Eigen::Matrix3d R_i = state_i.T_world_imu.linear();
  const Eigen::Matrix3d R_j = state_j.T_world_imu.linear();
  const Eigen::Vector3d dp_world = state_j.T_world_imu.translation() - state_i.T_world_imu.translation();
  const Eigen::Vector3d g = gravityWorld();
  Vector9d r;
  // Forster Eq. 45.
  r.segment<3>(0) = geometry::logSO3(correctedDeltaR(bias).transpose() * R_i.transpose() * R_j);
  r.segment<3>(3) = R_i.transpose() * (state_j.v_world - state_i.v_world - g * dt_) - correctedDeltaV(bias);
  r.segment<3>(6) =
      R_i.transpose() * (dp_world - state_i.v_world * dt_ - 0.5 * g * dt_ * dt_) - correctedDeltaP(bias);
  return r;
}

}  // namespace drover::imu
