#pragma once
// Rotating multi-beam lidar by ray casting. The head spins at `rate_hz`; column c of a sweep is fired at
// t_start + c / (columns * rate_hz) from the pose the robot has *at that instant*, so a sweep taken while moving is
// distorted exactly as a real one. Points are reported in the lidar frame at their own firing time, with
// per-point time offset and ring, like a Velodyne driver's output.
//
// Beam geometry: column c fires at azimuth +-2 pi c / columns from the lidar's +x axis (sign by spin_clockwise),
// ring r at elevation elevations[r]; direction (cos e cos a, cos e sin a, sin e) in the lidar frame. Column c's
// time offset is round(c * 1e9 / (rate_hz * columns)) ns. Rays with no hit within max_range, or a hit closer than
// min_range, give no point. Noise (when `noise`): range + N(0, sigma^2) and dropout draws keyed by
// (seed, Stream::kLidar, sweep_index, column, ring), so a scan is identical for any thread count.
#include <cstdint>
#include <string>
#include <vector>

#include "sim/trajectory.hpp"
#include "sim/world.hpp"
#include "types/lidar.hpp"

namespace drover::sim {

struct LidarModelConfig {
  // vlp16: 16 rings uniform over -15..+15 deg, 1800 columns, 100 m. vlp32: the VLP-32C table (-25..+15 deg, dense
  // 1/3 deg near the horizon), 1800 columns, 200 m. hdl64: two blocks (32 rings -24.9..-8.87 deg, 32 rings
  // -8.33..+2.0 deg at 1/3 deg), 2083 columns (0.1728 deg), 120 m -- an approximation of KITTI's HDL-64E. All 10 Hz.
  std::string model = "vlp16";       // vlp16 | vlp32 | hdl64 (sets the beam elevations below)
  std::vector<double> elevations;    // [rad] per ring, ascending (ring 0 = lowest); filled by forModel()
  int columns = 1800;                // firings per revolution
  double rate_hz = 10.0;             // [Hz] revolutions per second
  double min_range = 0.5;            // [m]
  double max_range = 100.0;          // [m]
  double range_noise_sigma = 0.02;   // [m], Gaussian
  // Dropout: a return is lost with probability that rises with distance and falls with reflectivity:
  // p = clamp(dropout_base + (range / max_range)^2 * (1 - reflectivity), 0, 1).
  double dropout_base = 0.01;
  bool noise = true;                 // false: exact ranges, no dropouts (tests)
  bool spin_clockwise = false;       // false: azimuth increases with time (counter-clockwise seen from above)
  static LidarModelConfig forModel(const std::string& model);  // throws std::invalid_argument for unknown names
  std::string validate() const;
};

// One sweep starting at t_start [ns]; T_body_lidar places the lidar on the body (= IMU). The scan's points are in
// the lidar frame at each point's firing time; intensity = reflectivity * 255 * cos(incidence) (Velodyne-like).
// Order: column-major, rings ascending within a column. scan.t = t_start, scan.t_end = last column's firing time.
// Throws std::invalid_argument for an invalid config, std::out_of_range when the sweep leaves the trajectory's span.
LidarScan simulateSweep(const World& world, const SplineTrajectory& trajectory, const Eigen::Isometry3d& T_body_lidar,
                        Time t_start, const LidarModelConfig& config, std::uint64_t seed, std::uint64_t sweep_index);

}  // namespace drover::sim
