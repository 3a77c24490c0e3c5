#pragma once
// The fixed-lag smoother tests' ground truth: a 12 s ground-robot wander with a noisy IMU of constant, known
// biases, and lidar-odometry-like noisy poses (tests/backend/test_fixed_lag_smoother*.cpp).
#include <cmath>
#include <random>
#include <vector>

#include "backend/pose_factors.hpp"
#include "geometry/so3.hpp"
#include "imu/preintegration.hpp"
#include "sim/imu_model.hpp"
#include "sim/trajectory.hpp"

namespace drover::backend::test {

constexpr Time kSec = 1'000'000'000;
constexpr Time kLidarPeriod = kSec / 10;  // 10 Hz lidar odometry

// A 12 s ground-robot wander: ~2-3 m/s, turning both ways, gentle pitch, roll and climb, knots every 0.5 s.
inline sim::SplineTrajectory wanderPath() {
  std::vector<sim::PathSample> samples;
  for (int k = 0; k <= 24; ++k) {
    const double t = 0.5 * k;
    sim::PathSample s;
    s.t = k * kSec / 2;
    s.p_world = {2.0 * t + std::sin(0.5 * t), 3.0 * std::sin(0.3 * t), 0.3 * std::sin(0.4 * t)};
    s.yaw = 0.2 * t + 0.5 * std::sin(0.4 * t);
    s.pitch = 0.04 * std::sin(0.7 * t);
    s.roll = 0.05 * std::cos(0.9 * t);
    samples.push_back(s);
  }
  return sim::SplineTrajectory(samples);
}

struct Scenario {
  sim::SplineTrajectory trajectory = wanderPath();
  sim::ImuModelConfig imu_model;
  std::vector<ImuSample> imu;
  imu::PreintegrationConfig preintegration;

  Scenario() {
    // Noisy IMU with constant, known biases (no random walk), as the smoother should recover them.
    imu_model.gyro_bias_random_walk = 0;
    imu_model.accel_bias_random_walk = 0;
    imu_model.initial_gyro_bias = {0.004, -0.003, 0.002};
    imu_model.initial_accel_bias = {0.05, -0.04, 0.06};
    imu = sim::simulateImu(trajectory, imu_model, 7);
    preintegration.gyro_noise_density = imu_model.gyro_noise_density;
    preintegration.acc_noise_density = imu_model.accel_noise_density;
  }

  imu::NavState truth(Time t) const {
    const sim::BodyState b = trajectory.at(t);
    return {t, b.T_world_body, b.v_world};
  }
};

// Lidar odometry: the true pose with N(0, sigma_p^2) on position and a right-perturbed N(0, sigma_r^2) rotation.
struct PoseNoise {
  double sigma_position = 0.02;  // [m]
  double sigma_rotation = 0.005; // [rad]
  std::mt19937 rng{11};
  Eigen::Isometry3d apply(Eigen::Isometry3d T) {
    std::normal_distribution<double> n(0.0, 1.0);
    T.translation() += sigma_position * Eigen::Vector3d(n(rng), n(rng), n(rng));
    T.linear() = T.linear() * geometry::expSO3(sigma_rotation * Eigen::Vector3d(n(rng), n(rng), n(rng)));
    return T;
  }
};

inline imu::Preintegrator preintegrate(const Scenario& s, Time t0, Time t1, const imu::ImuBias& bias_hat) {
  imu::Preintegrator pim(bias_hat, s.preintegration);
  pim.integrateRange(s.imu, t0, t1);
  return pim;
}

}  // namespace drover::backend::test
