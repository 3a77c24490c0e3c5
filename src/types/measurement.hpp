#pragma once
#include <variant>

#include "types/camera.hpp"
#include "types/imu.hpp"
#include "types/lidar.hpp"

namespace drover {

// What a reader yields: one measurement of any sensor, in global time order.
using Measurement = std::variant<ImuSample, LidarScan, CameraFrame>;

inline Time measurementTime(const Measurement& m) {
  return std::visit([](const auto& x) { return x.t; }, m);
}

}  // namespace drover
