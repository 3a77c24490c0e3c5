#pragma once
// IMU measurements from the analytic trajectory: omega_meas = omega_body + b_g + n_g,
// acc_meas = R_world_body^T (a_world - g_world) + b_a + n_a, with white noise n of continuous density sigma
// (discrete sigma / sqrt(dt)) and biases that random-walk with density sigma_b (discrete sigma_b * sqrt(dt)),
// as in the Kalibr IMU noise model. The body frame is the IMU frame.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/trajectory.hpp"
#include "types/imu.hpp"

namespace drover::sim {

struct ImuModelConfig {
  double rate_hz = 200.0;                       // [Hz]
  // Defaults of a low-cost 9-axis MEMS unit (order of an MPU-9250 / Xsens MTi-class consumer part).
  double gyro_noise_density = 1.7e-4;           // [rad/s/sqrt(Hz)]
  double accel_noise_density = 2.0e-3;          // [m/s^2/sqrt(Hz)]
  double gyro_bias_random_walk = 2.0e-5;        // [rad/s^2/sqrt(Hz)]
  double accel_bias_random_walk = 3.0e-4;       // [m/s^3/sqrt(Hz)]
  Eigen::Vector3d initial_gyro_bias = Eigen::Vector3d(0.002, -0.001, 0.0015);  // [rad/s]
  Eigen::Vector3d initial_accel_bias = Eigen::Vector3d(0.02, -0.03, 0.01);     // [m/s^2]
  double gravity = 9.81;                        // [m/s^2], along -z of the world
  bool noise = true;                            // false: exact measurements, zero biases (tests)
  bool orientation = true;                      // report q_world_imu (a 9-axis unit's own estimate: exact here)
  // Empty when valid: rate_hz > 0, densities, random walks and gravity >= 0 and finite, biases finite.
  std::string validate() const;
};

// Samples at t_k = start + round(k * 1e9 / rate) ns for every k with t_k <= trajectory.endTime() (the end is
// included when it falls on that grid). Noise (config.noise): white noise N(0, (density / sqrt(dt))^2) per axis;
// biases start at the initial biases at sample 0 and take one N(0, (sigma_b sqrt(dt))^2) step per later sample,
// dt = 1 / rate. Every normal is standardNormal(hashKeys(seed, Stream::kImu, k, channel)) with channel 0..2 gyro
// noise, 3..5 accel noise, 6..8 gyro bias step, 9..11 accel bias step, so output is a pure function of the
// seed. q_world_imu is the exact R_world_body when config.orientation. Throws std::invalid_argument when
// config.validate() fails.
// The biases the model walked, at every sample's stamp, in the IMU's frame (a dataset's ground truth).
struct ImuBiasSample {
  Time t = 0;                                          // [ns]
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();      // [rad/s]
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();     // [m/s^2]
};

// R_body_imu: the IMU's axes in the trajectory's body frame (columns); the measurements, the biases and the noise
// are in the IMU's frame, q_world_imu = R_world_body R_body_imu. Identity: the IMU is the body (every ground rig).
std::vector<ImuSample> simulateImu(const SplineTrajectory& trajectory, const ImuModelConfig& config,
                                   std::uint64_t seed,
                                   const Eigen::Matrix3d& R_body_imu = Eigen::Matrix3d::Identity(),
                                   std::vector<ImuBiasSample>* biases = nullptr);

}  // namespace drover::sim
