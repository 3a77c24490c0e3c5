#pragma once
// Motion compensation of one sweep (LIO-SAM imageProjection's deskewPoint): each point, measured in the lidar frame
// at its own firing time, is moved into the lidar frame at the sweep's start,
//   p_start = T_start_lidar(t) * p_lidar(t),
// given the lidar's motion over the sweep as T_start_lidar(t) (pose of the lidar at time offset t relative to the
// lidar at the sweep start; identity at t = 0). LIO-SAM compensates rotation only (from IMU integration) because its
// translation guess is unreliable; here the mode is a choice.
//
// Speed: the motion is sampled at `time_bins` + 1 evenly spaced times and each point uses the linear blend of its
// two neighbouring samples, an error of about range * (rotation per bin)^2 / 8 (< 0.02 mm at 50 m, 90 deg/s,
// 100 bins over 0.1 s) for a handful of motion evaluations per sweep instead of one per point.
#include <Eigen/Geometry>
#include <functional>
#include <string>

#include "types/lidar.hpp"

namespace drover::lidar {

// T_start_lidar(time_offset [s]): the lidar at time offset t expressed in the lidar frame at the sweep start.
using SweepMotion = std::function<Eigen::Isometry3d(double time_offset)>;

enum class DeskewMode {
  kNone,         // copy: points stay where they were measured
  kRotation,     // rotation only (LIO-SAM's default: only IMU rotation is trusted within a sweep)
  kTranslation,  // translation only
  kFull,         // rotation and translation
};

struct DeskewerConfig {
  DeskewMode mode = DeskewMode::kFull;
  int time_bins = 100;  // motion samples over [0, max time offset] minus one; >= 1
  std::string validate() const;  // empty when valid
};

enum class DeskewStatus {
  kOk,
  kEmpty,           // no points
  kNoTimeSpread,    // every point has the same time offset: nothing to compensate beyond T_start_lidar(0)
};

struct DeskewResult {
  DeskewStatus status = DeskewStatus::kOk;
  LidarScan scan;                 // points in the lidar frame at scan.t; ring, time, intensity, flags kept
  double max_time_offset = 0;     // [s] the latest point's offset (the span the motion was sampled over)
};

// Constant body twist over the sweep from the relative transform over one period: T_start_lidar(t) =
// Exp(t / period * Log(T_start_end)) (screw motion; extrapolates beyond the period). The usual model without an
// IMU, with T_start_end from the previous sweep's odometry. Throws std::invalid_argument for period <= 0.
SweepMotion constantVelocityMotion(const Eigen::Isometry3d& T_start_end, double period);

class Deskewer {
 public:
  // Throws std::invalid_argument when config.validate() fails.
  explicit Deskewer(const DeskewerConfig& config = {});

  // Requires per-point times (scan.has_time, measured or from inferTimes()); throws std::invalid_argument
  // otherwise, or when `motion` is empty. Negative or non-finite time offsets count as 0.
  DeskewResult deskew(const LidarScan& scan, const SweepMotion& T_start_lidar) const;

  const DeskewerConfig& config() const { return config_; }

 private:
  DeskewerConfig config_;
};

}  // namespace drover::lidar
