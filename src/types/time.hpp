#pragma once
// Time in Drover: signed 64-bit integer nanoseconds since the dataset's epoch. Convert to seconds only
// inside maths, with these helpers, so rounding happens in one place.
#include <cmath>
#include <cstdint>

namespace drover {

using Time = std::int64_t;  // [ns]

constexpr Time kNanosPerSecond = 1'000'000'000;

inline double toSeconds(Time t) { return static_cast<double>(t) * 1e-9; }

// Rounds to the nearest nanosecond. Seconds values from text files (e.g. "1403715274.30214") carry ~1e-7 s
// of double precision at epoch scale, which is far below any sensor's clock resolution.
inline Time fromSeconds(double s) { return static_cast<Time>(std::llround(s * 1e9)); }

}  // namespace drover
