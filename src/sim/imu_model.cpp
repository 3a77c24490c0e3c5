#include "sim/imu_model.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "sim/random.hpp"

namespace drover::sim {

namespace {

// Random-number channels within Stream::kImu, per sample index: white noise then bias-walk steps.
enum Channel : std::uint64_t { kGyroNoise = 0, kAccelNoise = 3, kGyroWalk = 6, kAccelWalk = 9 };

Eigen::Vector3d normal3(std::uint64_t seed, std::uint64_t k, std::uint64_t channel) {
  Eigen::Vector3d n;
  for (std::uint64_t axis = 0; axis < 3; ++axis) {
    n[static_cast<Eigen::Index>(axis)] = standardNormal(hashKeys(seed, Stream::kImu, k, channel + axis));
  }
  return n;
}

std::string checkNonNegative(const char* name, double value) {
  if (!std::isfinite(value) || value < 0) return std::string(name) + " = " + std::to_string(value) + " must be >= 0";
  return {};
}

}  // namespace

std::string ImuModelConfig::validate() const {
  if (!std::isfinite(rate_hz) || rate_hz <= 0) return "rate_hz = " + std::to_string(rate_hz) + " must be > 0";
  for (const auto& [name, value] : {std::pair{"gyro_noise_density", gyro_noise_density},
                                    std::pair{"accel_noise_density", accel_noise_density},
                                    std::pair{"gyro_bias_random_walk", gyro_bias_random_walk},
                                    std::pair{"accel_bias_random_walk", accel_bias_random_walk},
                                    std::pair{"gravity", gravity}}) {
    if (std::string e = checkNonNegative(name, value); !e.empty()) return e;
  }
  if (!initial_gyro_bias.allFinite()) return "initial_gyro_bias must be finite";
  if (!initial_accel_bias.allFinite()) return "initial_accel_bias must be finite";
  return {};
}

std::vector<ImuSample> simulateImu(const SplineTrajectory& trajectory, const ImuModelConfig& config,
                                   std::uint64_t seed, const Eigen::Matrix3d& R_body_imu,
                                   std::vector<ImuBiasSample>* biases) {
  if (const std::string error = config.validate(); !error.empty())
    throw std::invalid_argument("simulateImu: invalid ImuModelConfig: " + error);
  // Kalibr IMU noise model: discrete white-noise sigma_d = sigma / sqrt(dt), bias random-walk step
  // sigma_bd = sigma_b * sqrt(dt), with dt = 1 / rate the nominal sample period.
  const double dt = 1.0 / config.rate_hz;
  const double sigma_g = config.gyro_noise_density / std::sqrt(dt);
  const double sigma_a = config.accel_noise_density / std::sqrt(dt);
  const double sigma_bg = config.gyro_bias_random_walk * std::sqrt(dt);
  const double sigma_ba = config.accel_bias_random_walk * std::sqrt(dt);
  const Eigen::Vector3d g_world(0.0, 0.0, -config.gravity);

  const bool body_is_imu = R_body_imu == Eigen::Matrix3d::Identity();
  Eigen::Vector3d b_g = config.noise ? config.initial_gyro_bias : Eigen::Vector3d::Zero();
  Eigen::Vector3d b_a = config.noise ? config.initial_accel_bias : Eigen::Vector3d::Zero();
  std::vector<ImuSample> out;
  const Time start = trajectory.startTime(), end = trajectory.endTime();
  out.reserve(static_cast<std::size_t>(toSeconds(end - start) * config.rate_hz) + 2);
  for (std::uint64_t k = 0;; ++k) {
    const Time t = start + static_cast<Time>(std::llround(static_cast<double>(k) * 1e9 / config.rate_hz));
    if (t > end) break;
    const BodyState s = trajectory.at(t);
    Eigen::Matrix3d R_world_imu = s.T_world_body.linear();
    ImuSample m;
    m.t = t;
    m.omega_imu = s.omega_body;
    m.acc_imu = R_world_imu.transpose() * (s.a_world - g_world);  // specific force
    if (!body_is_imu) {  // skipped for the identity, so ground rigs keep their exact bits
      m.omega_imu = R_body_imu.transpose() * m.omega_imu;
      m.acc_imu = R_body_imu.transpose() * m.acc_imu;
      R_world_imu = R_world_imu * R_body_imu;
    }
    if (config.noise) {
      if (k > 0) {  // the biases walk between samples; sample 0 carries the initial biases
        b_g += sigma_bg * normal3(seed, k, kGyroWalk);
        b_a += sigma_ba * normal3(seed, k, kAccelWalk);
      }
      m.omega_imu += b_g + sigma_g * normal3(seed, k, kGyroNoise);
      m.acc_imu += b_a + sigma_a * normal3(seed, k, kAccelNoise);
    }
    if (config.orientation) m.q_world_imu = Eigen::Quaterniond(R_world_imu).normalized();
    if (biases != nullptr) biases->push_back({t, b_g, b_a});
    out.push_back(m);
  }
  return out;
}

}  // namespace drover::sim
