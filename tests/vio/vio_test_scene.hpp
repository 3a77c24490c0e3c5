#pragma once
// Synthetic initialisation windows with exact ground truth: a smooth trajectory (sinusoids in position and in
// roll/pitch/yaw), random 3-D points in front of a forward-looking camera, camera frames at 10 Hz and IMU samples
// at 200 Hz with a known gyroscope bias and no noise.
//
// The IMU samples are either the analytic body rate and specific force at their stamps (as a real IMU samples
// them), or their zero-order-hold equivalents, with which Drover's preintegrator holding each sample over its
// interval reproduces the true motion: the rate Log(R_k^T R_k+1) / dt and the specific force
// R_k^T ((v_k+1 - v_k) / dt - g). Rotation and velocity deltas are then exact and the position delta is the
// trapezoid rule of the true velocity (error ~1e-6 m over a frame interval).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "geometry/so3.hpp"
#include "vio/initial_alignment.hpp"

namespace drover::vio::test {

enum class Motion {
  kExcited,
  kStill,
  kRotationOnly,
  kConstantVelocity,
  kCarPullingAway,  // a car at 8 m/s accelerating at 1 m/s^2, straight; the road shakes it 4 mm up and down
  kCarInABend,      // the same car braking and accelerating through a bend (yaw 0.3 rad over the window)
};

struct SceneConfig {
  Motion motion = Motion::kExcited;
  int frames = 11;
  double camera_hz = 10;
  double imu_hz = 200;
  Eigen::Vector3d gyro_bias = Eigen::Vector3d(0.01, -0.02, 0.015);  // [rad/s]
  double gravity = 9.81;
  int points = 250;
  double near_m = 4, far_m = 12;  // [m] the points' distance ahead of the start
  double pixel_noise_px = 0;  // std of the image noise at focal_px
  double focal_px = 460;
  unsigned seed = 7;
  // true: zero-order-hold equivalents (exact under Drover's integration); false: the instantaneous analytic rate
  // and specific force at each sample's stamp, as a real IMU samples them (integration error O(dt)).
  bool hold_equivalent_samples = false;
};

struct Scene {
  std::vector<InitFrame> frames;
  Eigen::Isometry3d T_imu_cam = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Isometry3d> T_world_imu;  // ground truth per frame
  std::vector<Eigen::Vector3d> v_world;        // ground truth per frame [m/s]
  std::vector<Eigen::Vector3d> points_world;   // ground truth, feature id = index
};

// a sin(2 pi f t + phase) and its first two derivatives.
struct Sine {
  double a = 0, f = 0, phase = 0;
  double w() const { return 2 * M_PI * f; }
  double value(double t) const { return a * std::sin(w() * t + phase); }
  double rate(double t) const { return a * w() * std::cos(w() * t + phase); }
  double accel(double t) const { return -a * w() * w() * std::sin(w() * t + phase); }
};

struct Trajectory {
  Eigen::Vector3d p0 = Eigen::Vector3d(1, -2, 1.5), v0 = Eigen::Vector3d::Zero(), a0 = Eigen::Vector3d::Zero();
  Sine px, py, pz, roll, pitch, yaw;
  double yaw0 = 0.4;

  Eigen::Vector3d position(double t) const {
    return p0 + v0 * t + 0.5 * a0 * t * t + Eigen::Vector3d(px.value(t), py.value(t), pz.value(t));
  }
  Eigen::Vector3d velocity(double t) const { return v0 + a0 * t + Eigen::Vector3d(px.rate(t), py.rate(t), pz.rate(t)); }
  Eigen::Vector3d acceleration(double t) const { return a0 + Eigen::Vector3d(px.accel(t), py.accel(t), pz.accel(t)); }
  // Body rate: vee(R^T dR/dt) with dR/dt from the Euler-angle rates (R = Rz(yaw) Ry(pitch) Rx(roll)).
  Eigen::Vector3d bodyRate(double t) const {
    const Eigen::Matrix3d Rz = Eigen::AngleAxisd(yaw0 + yaw.value(t), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d Ry = Eigen::AngleAxisd(pitch.value(t), Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Matrix3d Rx = Eigen::AngleAxisd(roll.value(t), Eigen::Vector3d::UnitX()).toRotationMatrix();
    const Eigen::Matrix3d dR = Rz * geometry::hat(Eigen::Vector3d::UnitZ()) * yaw.rate(t) * Ry * Rx +
                               Rz * Ry * geometry::hat(Eigen::Vector3d::UnitY()) * pitch.rate(t) * Rx +
                               Rz * Ry * Rx * geometry::hat(Eigen::Vector3d::UnitX()) * roll.rate(t);
    return geometry::vee((Rz * Ry * Rx).transpose() * dR);
  }
  Eigen::Matrix3d rotation(double t) const {
    return (Eigen::AngleAxisd(yaw0 + yaw.value(t), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(pitch.value(t), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(roll.value(t), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
};

inline Trajectory trajectoryFor(Motion motion) {
  Trajectory tr;
  switch (motion) {
    case Motion::kExcited:  // walking forward while swaying, ~1 m over the second
      tr.v0 = Eigen::Vector3d(0.8, 0.1, 0);
      tr.px = {0.3, 0.5, 0.0};
      tr.py = {0.3, 0.7, 1.0};
      tr.pz = {0.15, 0.9, 0.5};
      tr.roll = {0.08, 0.6, 0.0};
      tr.pitch = {0.06, 0.5, 1.0};
      tr.yaw = {0.3, 0.4, 0.3};
      break;
    case Motion::kStill:  // a hand-held "still" snippet: ~2 cm of jitter, a few mrad of rotation
      tr.px = {0.008, 1.1, 0.0};
      tr.py = {0.006, 1.3, 1.0};
      tr.pz = {0.005, 0.9, 0.5};
      tr.roll = {0.003, 1.2, 0.0};
      tr.pitch = {0.002, 0.8, 1.0};
      tr.yaw = {0.003, 0.7, 0.3};
      break;
    case Motion::kRotationOnly:  // turning in place about the IMU: large image motion, no baseline
      tr.roll = {0.10, 0.6, 0.0};
      tr.pitch = {0.12, 0.5, 1.0};
      tr.yaw = {0.35, 0.4, 0.3};
      break;
    case Motion::kConstantVelocity:  // plenty of parallax, but no acceleration: the scale is unobservable
      tr.v0 = Eigen::Vector3d(1.0, 0.2, 0.05);
      break;
    case Motion::kCarPullingAway: {  // along the start's heading yaw0
      const Eigen::Vector3d ahead(std::cos(tr.yaw0), std::sin(tr.yaw0), 0);
      tr.v0 = 8.0 * ahead;
      tr.a0 = 1.0 * ahead;
      tr.pz = {0.004, 3.0, 0.0};  // 1.4 m/s^2 of vertical shake: passes VINS-Mono's excitation test
      break;
    }
    case Motion::kCarInABend: {
      const Eigen::Vector3d ahead(std::cos(tr.yaw0), std::sin(tr.yaw0), 0);
      tr.v0 = 8.0 * ahead;
      tr.px = {0.15, 0.6, 0.0};  // +-2.1 and 1.5 m/s^2 along x and y: braking, accelerating, the bend
      tr.py = {0.15, 0.5, 1.0};
      tr.pz = {0.004, 3.0, 0.0};
      tr.yaw = {0.3, 0.3, 0.0};
      tr.pitch = {0.01, 1.0, 0.5};
      break;
    }
  }
  return tr;
}

// Camera looking along the IMU x axis (IMU: x forward, z up; camera: z forward, y down), slightly rotated and
// offset, so that the extrinsic matters.
inline Eigen::Isometry3d testImuCam() {
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R * geometry::expSO3(Eigen::Vector3d(0.02, -0.03, 0.05));
  T.translation() = Eigen::Vector3d(0.10, -0.05, 0.03);
  return T;
}

inline Scene makeScene(const SceneConfig& config) {
  Scene scene;
  scene.T_imu_cam = testImuCam();
  const Trajectory tr = trajectoryFor(config.motion);
  std::mt19937 rng(config.seed);
  std::uniform_real_distribution<double> ux(config.near_m, config.far_m), uy(-6, 6), uz(-3, 4);
  std::normal_distribution<double> noise(0, config.pixel_noise_px / config.focal_px);
  std::vector<Eigen::Vector3d>& points = scene.points_world;
  for (int i = 0; i < config.points; ++i) points.push_back(tr.p0 + Eigen::AngleAxisd(tr.yaw0, Eigen::Vector3d::UnitZ()) *
                                                                     Eigen::Vector3d(ux(rng), uy(rng), uz(rng)));
  const Eigen::Vector3d g(0, 0, -config.gravity);
  const Time t_start = 1'000'000'000;
  const Time imu_dt = static_cast<Time>(std::llround(1e9 / config.imu_hz));
  const Time cam_dt = static_cast<Time>(std::llround(1e9 / config.camera_hz));
  const double dt = toSeconds(imu_dt);
  for (int k = 0; k < config.frames; ++k) {
    InitFrame frame;
    frame.t = t_start + k * cam_dt;
    const double t = toSeconds(frame.t - t_start);
    Eigen::Isometry3d T_wi = Eigen::Isometry3d::Identity();
    T_wi.linear() = tr.rotation(t);
    T_wi.translation() = tr.position(t);
    scene.T_world_imu.push_back(T_wi);
    scene.v_world.push_back(tr.velocity(t));
    const Eigen::Isometry3d T_cw = (T_wi * scene.T_imu_cam).inverse();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d pc = T_cw * points[i];
      if (pc.z() < 0.3) continue;
      const Eigen::Vector2d x = pc.hnormalized();
      if (std::abs(x.x()) > 0.7 || std::abs(x.y()) > 0.52) continue;  // 644 x 480 px at f = 460
      frame.features[i] = x + Eigen::Vector2d(noise(rng), noise(rng));
    }
    if (k > 0) {
      for (Time ts = frame.t - cam_dt; ts < frame.t; ts += imu_dt) {
        const double a = toSeconds(ts - t_start), b = a + dt;
        ImuSample s;
        s.t = ts;
        const Eigen::Matrix3d Ra = tr.rotation(a);
        if (config.hold_equivalent_samples) {
          s.omega_imu = geometry::logSO3(Ra.transpose() * tr.rotation(b)) / dt + config.gyro_bias;
          s.acc_imu = Ra.transpose() * ((tr.velocity(b) - tr.velocity(a)) / dt - g);
        } else {
          s.omega_imu = tr.bodyRate(a) + config.gyro_bias;
          s.acc_imu = Ra.transpose() * (tr.acceleration(a) - g);
        }
        frame.imu.push_back(s);
      }
    }
    scene.frames.push_back(frame);
  }
  return scene;
}

}  // namespace drover::vio::test
