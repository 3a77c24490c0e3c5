#pragma once
// Sensor faults the simulator can inject, each over a window of true time, so that a run's recovery can be measured
// against the same dataset without the fault (everything outside the windows is byte-identical to it: per-sample
// noise is keyed by the sample's index, which a fault never shifts).
//   camera-blackout: the lens is covered: no light reaches the sensor (frames hold read noise only), and the auto
//                    exposure opens up, so the first frames after the window are overexposed until it settles.
//   lidar-dropout:   no sweep that overlaps the window is written (a cable or driver fault).
//   imu-gap:         no IMU sample inside the window is written.
//   textureless:     every surface the camera sees renders in its plain colour (no texture; lighting and shading
//                    unchanged): fog on the lens or a freshly whitewashed barn. The lidar is unaffected.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "types/time.hpp"

namespace drover::sim {

enum class FaultKind { kCameraBlackout, kLidarDropout, kImuGap, kTextureless };
const char* faultName(FaultKind kind);                          // "camera-blackout", ...
std::optional<FaultKind> faultKind(std::string_view name);      // the inverse; nothing for an unknown name
std::vector<std::string> faultNames();

struct SensorFault {
  FaultKind kind = FaultKind::kCameraBlackout;
  Time start = 0, end = 0;  // [ns] true time (the trajectory's clock, as scenario segments)
  bool covers(Time t) const { return t >= start && t < end; }
  bool overlaps(Time t0, Time t1) const { return t0 < end && t1 > start; }
};

// Whether a fault of `kind` covers t.
bool faulted(const std::vector<SensorFault>& faults, FaultKind kind, Time t);
// Whether a fault of `kind` overlaps [t0, t1).
bool faulted(const std::vector<SensorFault>& faults, FaultKind kind, Time t0, Time t1);
// Empty when valid, else names the bad fault: each must have end > start, last at most 600 s.
std::string validateFaults(const std::vector<SensorFault>& faults);

}  // namespace drover::sim
