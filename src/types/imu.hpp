#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

#include "types/time.hpp"

namespace drover {

// One IMU measurement, all vectors in the IMU frame.
struct ImuSample {
  Time t = 0;                                          // [ns]
  Eigen::Vector3d omega_imu = Eigen::Vector3d::Zero(); // angular rate [rad/s]
  Eigen::Vector3d acc_imu = Eigen::Vector3d::Zero();   // specific force [m/s^2] (gravity included, as measured)
  // Orientation estimate of a 9-axis unit, R_world_imu, when the sensor provides one.
  std::optional<Eigen::Quaterniond> q_world_imu;
};

}  // namespace drover
