#pragma once
// The layout of a rotating multi-beam lidar's sweep (LIO-SAM's N_SCAN, Horizon_SCAN, ang_bottom...) and the repair
// of scans that lack per-point time or ring: KITTI's .bin files carry only x, y, z, reflectance.
//
// "Inferred" is signalled in the scan itself: inferTimes() sets LidarScan::has_time and inferRings() sets
// LidarScan::has_ring, so the deskewer and the feature extractor (which require them) accept the scan. Read the two
// flags as "the field is valid", measured or inferred.
#include <cstddef>
#include <string>

#include "types/lidar.hpp"

namespace drover::lidar {

enum class SpinDirection {
  kCounterClockwise,  // seen from above (+z): azimuth atan2(y, x) grows with time (HDL-64 in KITTI, the simulator)
  kClockwise,         // azimuth decreases with time
};

enum class RingSource {
  kElevation,  // ring from the elevation angle, beams uniform over the vertical FOV (VLP-16, VLP-32 "uniform")
  kOrder,      // ring from point order: the lidar emits ring by ring, one revolution each (KITTI HDL-64)
};

struct ScanLayoutConfig {
  int n_rings = 16;                    // beams (LIO-SAM N_SCAN)
  double vertical_fov_min_deg = -15;   // [deg] elevation of the lowest beam (LIO-SAM ang_bottom, sign flipped)
  double vertical_fov_max_deg = 15;    // [deg] elevation of the highest beam
  int columns = 1800;                  // firings per revolution (LIO-SAM Horizon_SCAN)
  double scan_period = 0.1;            // [s] one revolution (1 / rotation rate)
  SpinDirection spin = SpinDirection::kCounterClockwise;
  RingSource ring_source = RingSource::kElevation;
  // kOrder only: the first ring in point order is the highest beam (KITTI: rings run top to bottom); ring 0 is
  // always the lowest beam in the output.
  bool order_top_down = false;
  // [deg] points up to this far *before* the first point's azimuth count as the sweep's start (time 0), not its
  // end: beams of one firing differ by a few hundredths of a degree, and float rounding is smaller still.
  double seam_tolerance_deg = 0.1;
  double min_range = 1.0;              // [m] closer returns are dropped (LIO-SAM lidarMinRange; the vehicle itself)
  double max_range = 100.0;            // [m] farther returns are dropped (LIO-SAM lidarMaxRange)

  // Velodyne VLP-16: 16 beams uniform over -15..+15 deg, 1800 columns at 10 Hz; rings by elevation.
  static ScanLayoutConfig vlp16();
  // KITTI's HDL-64E .bin scans: 64 beams over about -24.9..+2 deg, rings by order (top to bottom), 10 Hz.
  static ScanLayoutConfig kittiHdl64();

  std::string validate() const;  // empty when valid
};

enum class InferenceStatus {
  kOk,
  kEmpty,             // no points: nothing inferred, flags left unchanged
  kRingCountMismatch, // kOrder found a different number of revolutions than n_rings (rings clamped)
};

struct TimeInference {
  InferenceStatus status = InferenceStatus::kOk;
  double max_time_offset = 0;  // [s] the latest point's offset, in [0, scan_period)
};

struct RingInference {
  InferenceStatus status = InferenceStatus::kOk;
  int rings_found = 0;          // distinct rings assigned (kOrder: revolutions found)
  std::size_t clamped = 0;      // points whose ring fell outside [0, n_rings) and was clamped to the nearest
};

struct SanitizeResult {
  std::size_t kept = 0;
  std::size_t non_finite = 0;   // NaN or inf in x, y or z
  std::size_t too_close = 0;    // range < min_range
  std::size_t too_far = 0;      // range > max_range
};

// Time offset [s] of every point from its azimuth, for scans without per-point time: the first point defines the
// sweep start; time = (azimuth travelled since it in the spin direction) / (2 pi) * scan_period, in
// [0, scan_period) (0 for a non-finite point). Sets has_time = true and
// scan.t_end = scan.t + the largest offset. Throws
// std::invalid_argument for an invalid config.
TimeInference inferTimes(LidarScan& scan, const ScanLayoutConfig& config);

// Ring of every point (ring 0 = lowest beam), by config.ring_source; sets has_ring = true. kOrder detects a new
// ring where the azimuth, measured from the first point's in the spin direction, wraps around from near 2 pi to
// near 0 after the current ring has covered more than half a revolution (so jitter at the seam is ignored);
// a non-finite point gets the ring of the points around it.
// Throws std::invalid_argument for an invalid config.
RingInference inferRings(LidarScan& scan, const ScanLayoutConfig& config);

// Drops non-finite points and points with range outside [min_range, max_range], keeping the order of the rest.
// Throws std::invalid_argument for an invalid config.
SanitizeResult sanitize(LidarScan& scan, const ScanLayoutConfig& config);

}  // namespace drover::lidar
