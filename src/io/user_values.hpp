#pragma once
// Every number a user types -- a command-line option or a key of a platform config -- becomes a checked value here,
// so one rule holds for all of them: the whole text is a number of the expected kind, it is finite, and it lies in
// the documented range (NaN fails every range check). A failure is an IoError naming where the value came from (the
// option, or the config file, line and dotted key), the value (shortened) and the valid range; the CLI prints it as
// one `[error]` line and exits with code 2.
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include "types/time.hpp"

namespace drover::io {

// Where a value came from, for messages: an option (file "--t-offset", no record) or a config key (the config
// file, record "line 12, key 'sim.imu_rate_hz'").
struct ValueSource {
  std::string file;
  std::string record;
  static ValueSource option(std::string name) { return {std::move(name), ""}; }
};

// Throws IoError(source.file, source.record, what).
[[noreturn]] void failValue(const ValueSource& source, const std::string& what);

// An interval of doubles: [min, max], either end open, in `unit` ("s", "Hz", "m", "" for none).
struct Range {
  double min = -std::numeric_limits<double>::max();
  double max = std::numeric_limits<double>::max();
  bool min_open = false, max_open = false;
  const char* unit = "";

  bool contains(double v) const;  // false for NaN
  std::string describe() const;   // "(0, 1]", "[0, 3600] s"
};

Range atLeast(double min, const char* unit);              // [min, inf)
Range positive(const char* unit);                         // (0, inf)
Range between(double min, double max, const char* unit);  // [min, max]

// The largest magnitude of user-given seconds [s] (~127 years): beyond any Unix-epoch stamp (1.7e9 s in 2024), and
// far inside int64 nanoseconds (9.2e9 s), so stamps shifted by it do not overflow.
constexpr double kMaxSeconds = 4.0e9;

// Whole text as a finite number ("1e-3", "-2.5", "+4"); "", "1.5x", "nan", "inf" and overflow ("1e400") fail.
double parseNumber(std::string_view text, const ValueSource& source);
// `value` when range.contains(value); otherwise fails naming the value and the range.
double checkedNumber(double value, const Range& range, const ValueSource& source);
double parseNumber(std::string_view text, const Range& range, const ValueSource& source);

// Seconds to Time [ns], rounded to the nearest nanosecond: within `range` and within +-kMaxSeconds (say which).
Time checkedSeconds(double seconds, const Range& range, const ValueSource& source);
Time parseSecondsValue(std::string_view text, const Range& range, const ValueSource& source);

// A rate [Hz]: finite, > 0 and <= max_hz.
double checkedRate(double hz, double max_hz, const ValueSource& source);

// Whole text as an integer in [min, max] (digits with an optional sign; "1.5", "1e3", "0x10" fail): out of range,
// including beyond 64 bits ("2^70"), fails naming the range rather than wrapping.
std::int64_t parseInteger(std::string_view text, std::int64_t min, std::int64_t max, const ValueSource& source);
// A random seed: an integer in [0, 2^64 - 1], parsed exactly ("-1" and 2^64 fail, nothing wraps).
std::uint64_t parseSeed(std::string_view text, const ValueSource& source);

}  // namespace drover::io
