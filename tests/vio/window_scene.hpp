#pragma once
// A synthetic visual-inertial scene with exact ground truth for the sliding-window tests: a smooth 3D trajectory
// (a circle with height and heading waves), its analytic IMU (body rate, specific force, constant biases added),
// landmarks on a cylinder around the path, and per camera frame the ideal normalised observations with their
// image velocities. World z up, gravity (0, 0, -9.81); camera z forward.
#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "types/imu.hpp"
#include "types/time.hpp"
#include "vio/feature_manager.hpp"

namespace drover::vio::test {

struct SceneTruth {
  Eigen::Isometry3d T_world_imu;
  Eigen::Vector3d v_world;
};

class WindowScene {
 public:
  double radius = 6.0;       // [m] of the circle driven
  double speed = 1.5;        // [m/s]
  double wave = 0.4;         // [m] height wave amplitude
  double yaw_wave = 0.25;    // [rad] heading wave on top of the tangent
  Eigen::Vector3d gyro_bias{0.004, -0.003, 0.002};  // [rad/s]
  Eigen::Vector3d acc_bias{0.03, -0.02, 0.04};      // [m/s^2]
  Eigen::Isometry3d T_imu_cam = defaultExtrinsic();
  double gravity = 9.81;

  static Eigen::Isometry3d defaultExtrinsic() {
    // Camera looking along the body x axis (forward), z_cam = x_body, x_cam = -y_body, y_cam = -z_body.
    Eigen::Matrix3d R;
    R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R;
    T.translation() = Eigen::Vector3d(0.05, 0.02, -0.03);
    return T;
  }

  explicit WindowScene(int landmarks = 1500, unsigned seed = 3) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> angle(0, 2 * M_PI), height(-1.5, 2.5), r(radius + 3.0, radius + 7.0);
    for (int k = 0; k < landmarks; ++k) {
      const double a = angle(rng), rr = r(rng);
      points.emplace_back(rr * std::cos(a), rr * std::sin(a), height(rng));
    }
  }

  // Position, velocity and acceleration of the IMU in the world at t [s].
  Eigen::Vector3d position(double t) const {
    const double w = speed / radius;
    return {radius * std::sin(w * t), radius * (1 - std::cos(w * t)), wave * std::sin(0.7 * t)};
  }
  Eigen::Vector3d velocity(double t) const {
    const double w = speed / radius;
    return {radius * w * std::cos(w * t), radius * w * std::sin(w * t), wave * 0.7 * std::cos(0.7 * t)};
  }
  Eigen::Vector3d acceleration(double t) const {
    const double w = speed / radius;
    return {-radius * w * w * std::sin(w * t), radius * w * w * std::cos(w * t), -wave * 0.49 * std::sin(0.7 * t)};
  }
  // Heading along the circle plus a wave, a little roll and pitch.
  Eigen::Vector3d ypr(double t) const {
    const double w = speed / radius;
    return {w * t + yaw_wave * std::sin(1.1 * t), 0.05 * std::sin(0.9 * t), 0.04 * std::cos(1.3 * t)};
  }
  Eigen::Vector3d yprRate(double t) const {
    const double w = speed / radius;
    return {w + yaw_wave * 1.1 * std::cos(1.1 * t), 0.05 * 0.9 * std::cos(0.9 * t), -0.04 * 1.3 * std::sin(1.3 * t)};
  }
  static Eigen::Matrix3d rotation(const Eigen::Vector3d& ypr) {
    return (Eigen::AngleAxisd(ypr.x(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(ypr.y(), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(ypr.z(), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
  SceneTruth truth(double t) const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = rotation(ypr(t));
    T.translation() = position(t);
    return {T, velocity(t)};
  }
  // Body angular rate by differentiating R (central difference of the exact rotation, 1e-5 s: error ~1e-10).
  Eigen::Vector3d omegaBody(double t) const {
    const double h = 1e-5;
    const Eigen::Matrix3d dR = rotation(ypr(t - h)).transpose() * rotation(ypr(t + h));
    const Eigen::AngleAxisd aa(dR);
    return aa.axis() * aa.angle() / (2 * h);
  }
  ImuSample imu(double t) const {
    ImuSample s;
    s.t = fromSeconds(t);
    const Eigen::Matrix3d R = rotation(ypr(t));
    s.omega_imu = omegaBody(t) + gyro_bias;
    s.acc_imu = R.transpose() * (acceleration(t) + Eigen::Vector3d(0, 0, gravity)) + acc_bias;
    return s;
  }
  // The landmarks seen from the camera at t (inside a 90 x 70 degree field, 1..20 m), id = landmark index.
  std::vector<FrameFeature> features(double t, double max_features = 150) const {
    std::vector<FrameFeature> out;
    const Eigen::Isometry3d T_wc = truth(t).T_world_imu * T_imu_cam;
    const Eigen::Isometry3d T_wc2 = truth(t + 1e-3).T_world_imu * T_imu_cam;
    for (std::size_t k = 0; k < points.size() && out.size() < max_features; ++k) {
      const Eigen::Vector3d p = T_wc.inverse() * points[k];
      if (p.z() < 1.0 || p.z() > 20.0 || std::abs(p.x() / p.z()) > 1.0 || std::abs(p.y() / p.z()) > 0.7) continue;
      const Eigen::Vector3d p2 = T_wc2.inverse() * points[k];
      FrameFeature f;
      f.id = k;
      f.normalized = p.hnormalized();
      f.velocity = (p2.hnormalized() - f.normalized) / 1e-3;
      f.lidar_depth = 0;
      out.push_back(f);
    }
    return out;
  }
  std::vector<Eigen::Vector3d> points;
};

}  // namespace drover::vio::test
