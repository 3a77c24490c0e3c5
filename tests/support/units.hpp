#pragma once
// The units test files write durations and angles in, defined once: a module's test files compile as unity batches
// (tests/CMakeLists.txt), where two files' own `constexpr Time kSec` would be one definition too many.
#include <numbers>

#include "types/time.hpp"

namespace drover::test {

inline constexpr Time kSec = kNanosPerSecond;      // [ns] one second
inline constexpr Time kMs = kNanosPerSecond / 1000;  // [ns] one millisecond
inline constexpr double kPi = std::numbers::pi;
inline constexpr double kDeg = std::numbers::pi / 180;  // [rad] one degree

}  // namespace drover::test
