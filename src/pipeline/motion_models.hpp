#pragma once
// Motion of the lidar over a sweep and initial guesses, from the IMU propagation or, without an IMU, from a
// constant-velocity model of the last two poses (LIO-SAM falls back to the previous pose; constant velocity is
// the usual LOAM-family choice and is much better at car speeds). The constant-velocity sweep motion itself is
// lidar::constantVelocityMotion (lidar/deskew.hpp).
#include <Eigen/Geometry>
#include <optional>

#include "imu/propagator.hpp"
#include "lidar/deskew.hpp"
#include "types/time.hpp"

namespace drover::pipeline {

// The pose at dt [s] after `last`, continuing T_prev_last (observed over dt_prev [s]) at constant velocity:
// T_world_last Exp(dt / dt_prev Log(T_prev_last)). T_world_last itself when dt_prev or dt is not positive.
Eigen::Isometry3d constantVelocityGuess(const Eigen::Isometry3d& T_world_last, const Eigen::Isometry3d& T_prev_last,
                                        double dt_prev, double dt);

// Sweep motion from the IMU propagation: T_start_lidar(tau) = (T_w_i(t0) T_i_l)^-1 T_w_i(t0 + tau) T_i_l.
// std::nullopt unless the propagator covers [t0, t_end]. The deskewer samples it at a hundred or so times per
// sweep; each is one binary search and one integration step in the propagator. The propagator must outlive the
// returned function's use.
std::optional<lidar::SweepMotion> imuMotion(const imu::ImuPropagator& propagator, const Eigen::Isometry3d& T_imu_lidar,
                                            Time t0, Time t_end);

}  // namespace drover::pipeline
