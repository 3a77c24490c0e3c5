#pragma once
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
};

}  // namespace drover
