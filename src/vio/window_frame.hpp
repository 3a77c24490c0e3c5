#pragma once
// One frame of the sliding window with its Ceres parameter blocks (vio-internal header).
#include <Eigen/Geometry>
#include <map>
#include <optional>
#include <vector>

#include "imu/preintegration.hpp"
#include "types/imu.hpp"
#include "vio/sliding_window.hpp"

namespace drover::vio {

struct SlidingWindowEstimator::Frame {
  Time t = 0;                                    // [ns] IMU time
  double p[3] = {0, 0, 0};                       // p_world_imu [m]
  double q[4] = {0, 0, 0, 1};                    // q_world_imu (x, y, z, w)
  double v[3] = {0, 0, 0};                       // v_world [m/s]
  double bias[6] = {0, 0, 0, 0, 0, 0};           // [b_g rad/s; b_a m/s^2]
  std::vector<ImuSample> imu;                    // samples covering [previous frame's t, t]
  std::optional<imu::Preintegrator> pre;         // previous frame -> this one
  std::map<std::uint64_t, Eigen::Vector2d> seen; // feature id -> normalised coordinates (visual initialisation)

  Eigen::Isometry3d pose() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
    T.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
    return T;
  }
  void setPose(const Eigen::Isometry3d& T) {
    const Eigen::Quaterniond r(T.rotation());
    q[0] = r.x(), q[1] = r.y(), q[2] = r.z(), q[3] = r.w();
    Eigen::Map<Eigen::Vector3d>{p} = T.translation();
  }
  Eigen::Vector3d velocity() const { return Eigen::Vector3d(v[0], v[1], v[2]); }
  void setVelocity(const Eigen::Vector3d& vel) { Eigen::Map<Eigen::Vector3d>{v} = vel; }
  imu::ImuBias imuBias() const {
    imu::ImuBias b;
    b.gyro = Eigen::Vector3d(bias[0], bias[1], bias[2]);
    b.acc = Eigen::Vector3d(bias[3], bias[4], bias[5]);
    return b;
  }
  void setBias(const imu::ImuBias& b) {
    Eigen::Map<Eigen::Vector3d>{bias} = b.gyro;
    Eigen::Map<Eigen::Vector3d>{bias + 3} = b.acc;
  }
};

}  // namespace drover::vio
