#pragma once
// A reader that reads ahead: another reader's next() runs in one worker thread, a bounded queue ahead of the
// caller, so decoding the PNGs and parsing the lidar files (~50 s of the farm course's 650 s with a camera) overlaps
// the odometry instead of adding to it. The stream is the inner reader's, measurement for measurement, so a replay
// stays deterministic. An exception the inner reader throws is rethrown by next() at the position it was thrown,
// after the measurements read before it; drops() follow the measurements handed out, as the inner reader's did.
#include <cstddef>
#include <memory>

#include "io/reader.hpp"

namespace drover::io {

// Wraps `inner` (which must not be used by anyone else afterwards). `capacity`: measurements queued ahead at most
// (>= 1; 64 is ~0.3 s of a 200 Hz IMU with a 10 Hz lidar and a 15 Hz camera, ~5 MB of scans and images).
std::unique_ptr<Reader> readAhead(std::unique_ptr<Reader> inner, std::size_t capacity = 64);

}  // namespace drover::io
