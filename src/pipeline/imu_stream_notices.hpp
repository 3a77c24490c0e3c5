#pragma once
// One warning line per IMU stream problem (gap, spike, non-finite or out-of-order sample), as the README promises,
// capped per kind so a broken IMU at 200 Hz cannot flood the terminal: the counters in ImuStreamStats count every
// problem, these lines show the first few of each kind and then say that the rest are only counted.
#include <array>
#include <cstddef>
#include <optional>
#include <string>

#include "imu/propagator.hpp"
#include "types/imu.hpp"

namespace drover::pipeline {

class ImuStreamNotices {
 public:
  static constexpr std::size_t kPerKind = 5;  // lines shown per problem kind before only counting

  // The line to show for `sample` added with `status` (nullopt when it was accepted normally, or when this kind's
  // lines are used up). `previous` is the stamp of the accepted sample before it [ns] (for the gap's length).
  std::optional<std::string> onSample(const ImuSample& sample, imu::SampleStatus status, std::optional<Time> previous);

 private:
  std::array<std::size_t, 5> shown_{};  // per SampleStatus
};

}  // namespace drover::pipeline
