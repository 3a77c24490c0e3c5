#pragma once
// sensor_msgs/PointCloud2 -> LidarScan for any field layout (Velodyne, Ouster, Hesai, Livox-converted...).
//
// Fields used, by name:
//   x, y, z         float32 or float64 (required)
//   intensity       float32/float64/uint8/uint16/uint32 (absent -> 0)
//   ring            uint8 or uint16 (absent -> has_ring = false)
//   time | t | timestamp (first present wins): float32/float64 seconds relative to the header stamp, or uint32
//                   nanoseconds relative to it (Ouster "t"); a float64 above 1e6 s is taken as absolute Unix time
//                   (Hesai "timestamp"). Absent -> has_time = false.
// Other fields and padding are skipped via their offsets, point_step and row_step. A used field with another
// datatype, a field reaching past point_step, data shorter than the layout needs, or big-endian data -> error.
//
// Sweep time: per-point times are offsets from the header stamp and may be negative (drivers that stamp the
// sweep end). LidarScan::t is the sweep start = stamp + min(0, smallest offset), so every time_offset >= 0 and
// a stamp that already marks the start is kept as is; t_end = stamp + largest offset (t_end = t without times).
// Points with a non-finite coordinate, intensity or time (organised clouds mark missing returns with NaN) are
// dropped and counted.
#include <cstddef>
#include <cstdint>

#include "types/lidar.hpp"

namespace drover::io::ros {

struct DecodedCloud {
  LidarScan scan;
  Time stamp = 0;                   // [ns] header stamp
  std::size_t dropped_nonfinite = 0;  // points dropped for NaN/inf values
};

// Throws MessageError on malformed messages or unsupported layouts.
DecodedCloud decodePointCloud2(const std::uint8_t* data, std::size_t size);

}  // namespace drover::io::ros
