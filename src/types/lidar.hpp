#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "types/time.hpp"

namespace drover {

// One lidar return in the lidar frame.
struct LidarPoint {
  float x = 0, y = 0, z = 0;  // [m], lidar frame
  float intensity = 0;        // sensor units (KITTI reflectance 0..1, Velodyne 0..255)
  float time_offset = 0;      // [s] since LidarScan::t (the sweep's start); valid when LidarScan::has_time
  std::uint16_t ring = 0;     // laser index, 0 = lowest beam; valid when LidarScan::has_ring
};

// One sweep. `t` is the time of the sweep's first point; per-point times are offsets from it.
struct LidarScan {
  Time t = 0;               // [ns] start of the sweep
  Time t_end = 0;           // [ns] end of the sweep (== t when unknown)
  bool has_time = false;    // per-point time_offset is valid: measured by the lidar, or set by lidar::inferTimes()
  bool has_ring = false;    // per-point ring is valid: measured by the lidar, or set by lidar::inferRings()
  std::vector<LidarPoint> points;
  // Points the reader dropped because a value (coordinate, intensity, time) was NaN or inf: a real lidar's
  // missing returns. Not in `points`; counted and warned about by whoever consumes the scan.
  std::size_t dropped_nonfinite = 0;
};

}  // namespace drover
