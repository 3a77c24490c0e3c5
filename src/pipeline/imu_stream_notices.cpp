#include "pipeline/imu_stream_notices.hpp"

#include <fmt/format.h>

namespace drover::pipeline {
namespace {

std::string describe(const ImuSample& s, imu::SampleStatus status, std::optional<Time> previous) {
  const double t = toSeconds(s.t);
  switch (status) {
    case imu::SampleStatus::kAcceptedAfterGap:
      return fmt::format("IMU gap of {:.3f} s before the sample at {:.6f} s: bridged by propagation",
                         previous ? toSeconds(s.t - *previous) : 0.0, t);
    case imu::SampleStatus::kDroppedSpike:
      return fmt::format("IMU sample at {:.6f} s dropped: spike (|a| = {:.1f} m/s^2, |w| = {:.2f} rad/s)", t,
                         s.acc_imu.norm(), s.omega_imu.norm());
    case imu::SampleStatus::kDroppedNonFinite:
      return fmt::format("IMU sample at {:.6f} s dropped: non-finite value", t);
    case imu::SampleStatus::kDroppedOutOfOrder:
      return fmt::format("IMU sample at {:.6f} s dropped: its stamp is not after the previous sample's ({:.6f} s)", t,
                         previous ? toSeconds(*previous) : 0.0);
    case imu::SampleStatus::kAccepted: break;
  }
  return {};
}

}  // namespace

std::optional<std::string> ImuStreamNotices::onSample(const ImuSample& sample, imu::SampleStatus status,
                                                      std::optional<Time> previous) {
  if (status == imu::SampleStatus::kAccepted) return std::nullopt;
  std::size_t& shown = shown_[static_cast<std::size_t>(status)];
  if (shown > kPerKind) return std::nullopt;
  ++shown;
  if (shown > kPerKind)
    return fmt::format("further IMU problems of this kind ({}) are not shown; report.json counts them all",
                       imu::toString(status));
  return describe(sample, status, previous);
}

}  // namespace drover::pipeline
