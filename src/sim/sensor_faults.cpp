#include "sim/sensor_faults.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <utility>

namespace drover::sim {
namespace {

constexpr std::array<std::pair<FaultKind, const char*>, 4> kNames{{{FaultKind::kCameraBlackout, "camera-blackout"},
                                                                   {FaultKind::kLidarDropout, "lidar-dropout"},
                                                                   {FaultKind::kImuGap, "imu-gap"},
                                                                   {FaultKind::kTextureless, "textureless"}}};
constexpr double kMaxFaultS = 600.0;  // [s]

}  // namespace

const char* faultName(FaultKind kind) {
  for (const auto& [k, name] : kNames)
    if (k == kind) return name;
  return "unknown";
}

std::optional<FaultKind> faultKind(std::string_view name) {
  for (const auto& [k, n] : kNames)
    if (name == n) return k;
  return std::nullopt;
}

std::vector<std::string> faultNames() {
  std::vector<std::string> out;
  for (const auto& entry : kNames) out.emplace_back(entry.second);
  return out;
}

bool faulted(const std::vector<SensorFault>& faults, FaultKind kind, Time t) {
  return std::any_of(faults.begin(), faults.end(), [&](const SensorFault& f) { return f.kind == kind && f.covers(t); });
}

bool faulted(const std::vector<SensorFault>& faults, FaultKind kind, Time t0, Time t1) {
  return std::any_of(faults.begin(), faults.end(),
                     [&](const SensorFault& f) { return f.kind == kind && f.overlaps(t0, t1); });
}

std::string validateFaults(const std::vector<SensorFault>& faults) {
  for (const SensorFault& f : faults) {
    if (!(f.end > f.start))
      return fmt::format("fault {} at {:.3f} s: its duration must be > 0", faultName(f.kind), toSeconds(f.start));
    if (toSeconds(f.end - f.start) > kMaxFaultS)
      return fmt::format("fault {} at {:.3f} s: lasts {:.1f} s, more than {:.0f} s", faultName(f.kind),
                         toSeconds(f.start), toSeconds(f.end - f.start), kMaxFaultS);
  }
  return {};
}

}  // namespace drover::sim
