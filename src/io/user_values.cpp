#include "io/user_values.hpp"

#include <charconv>
#include <cmath>
#include <system_error>

#include "io/error.hpp"
#include "io/text_parsing.hpp"

namespace drover::io {
namespace {

std::string_view withoutPlus(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);  // from_chars rejects a leading '+'
  return s;
}

bool isInteger(std::string_view s) {
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) s.remove_prefix(1);
  if (s.empty()) return false;
  for (char c : s)
    if (c < '0' || c > '9') return false;
  return true;
}

// Whole numbers below 1e15 in full ("4000000000", not "4e+09"), others as the shortest round-trip text.
std::string shown(double v) {
  if (std::abs(v) < 1e15 && v == std::floor(v)) return std::to_string(static_cast<std::int64_t>(v));
  return formatDouble(v);
}

std::string withUnit(const std::string& text, const char* unit) {
  return *unit ? text + " " + unit : text;
}

}  // namespace

void failValue(const ValueSource& source, const std::string& what) { fail(source.file, source.record, what); }

bool Range::contains(double v) const {
  const bool above = min_open ? v > min : v >= min;
  const bool below = max_open ? v < max : v <= max;
  return above && below;  // both false for NaN
}

std::string Range::describe() const {
  const auto bound = [](double v) {
    if (v >= std::numeric_limits<double>::max()) return std::string("inf");
    if (v <= -std::numeric_limits<double>::max()) return std::string("-inf");
    return shown(v);
  };
  // Appended piece by piece: GCC 12's -Wrestrict misfires on "literal" + std::string chains.
  std::string text = min_open ? "(" : "[";
  text += bound(min);
  text += ", ";
  text += bound(max);
  text += max_open ? ")" : "]";
  return withUnit(text, unit);
}

Range atLeast(double min, const char* unit) {
  Range r;
  r.min = min;
  r.unit = unit;
  return r;
}

Range positive(const char* unit) {
  Range r = atLeast(0, unit);
  r.min_open = true;
  return r;
}

Range between(double min, double max, const char* unit) {
  Range r = atLeast(min, unit);
  r.max = max;
  return r;
}

double parseNumber(std::string_view text, const ValueSource& source) {
  const std::string_view s = withoutPlus(text);
  double value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ptr != s.data() + s.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
    failValue(source, "not a number: " + echo(text));
  // from_chars reports overflow ("1e400") as out of range; NaN and inf parse as themselves.
  if (ec == std::errc::result_out_of_range || !std::isfinite(value))
    failValue(source, "expected a finite number, got " + echo(text));
  return value;
}

double checkedNumber(double value, const Range& range, const ValueSource& source) {
  if (!range.contains(value))
    failValue(source, withUnit(shown(value), range.unit) + " is out of range (expected " + range.describe() + ")");
  return value;
}

double parseNumber(std::string_view text, const Range& range, const ValueSource& source) {
  return checkedNumber(parseNumber(text, source), range, source);
}

Time checkedSeconds(double seconds, const Range& range, const ValueSource& source) {
  checkedNumber(seconds, range, source);
  if (!(std::abs(seconds) <= kMaxSeconds))
    failValue(source, shown(seconds) + " s is beyond the largest time accepted, +-" + shown(kMaxSeconds) +
                          " s (about 127 years)");
  return static_cast<Time>(std::llround(seconds * 1e9));
}

Time parseSecondsValue(std::string_view text, const Range& range, const ValueSource& source) {
  return checkedSeconds(parseNumber(text, source), range, source);
}

double checkedRate(double hz, double max_hz, const ValueSource& source) {
  Range r = positive("Hz");
  r.max = max_hz;
  return checkedNumber(hz, r, source);
}

std::int64_t parseInteger(std::string_view text, std::int64_t min, std::int64_t max, const ValueSource& source) {
  std::string range = "[";
  range += std::to_string(min);
  range += ", ";
  range += std::to_string(max);
  range += "]";
  if (!isInteger(text)) failValue(source, "expected an integer in " + range + ", got " + echo(text));
  const std::string_view s = withoutPlus(text);
  std::int64_t value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || ptr != s.data() + s.size() || value < min || value > max)
    failValue(source, echo(text) + " is out of range (expected an integer in " + range + ")");
  return value;
}

std::uint64_t parseSeed(std::string_view text, const ValueSource& source) {
  const char* range = "[0, 18446744073709551615]";
  if (!isInteger(text)) failValue(source, "expected an integer seed in " + std::string(range) + ", got " + echo(text));
  std::string_view s = withoutPlus(text);
  if (s.front() == '-' && s.find_first_not_of('0', 1) == std::string_view::npos) s.remove_prefix(1);  // "-0" is 0
  std::uint64_t value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);  // "-1" fails here, never wraps
  if (ec != std::errc() || ptr != s.data() + s.size())
    failValue(source, echo(text) + " is out of range (expected an integer seed in " + std::string(range) + ")");
  return value;
}

}  // namespace drover::io
