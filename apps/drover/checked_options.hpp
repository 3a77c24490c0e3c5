#pragma once
// Numeric options go through io/user_values.hpp, the one place that turns user-given numbers into checked values
// (config keys use it too): the text is parsed exactly and range-checked while the command line is read, so a bad
// value stops the command before any work with one `[error] --option: ...` line naming the valid range.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

#include "io/user_values.hpp"

namespace drover::cli {

// A number in `range` (NaN, inf and anything outside fail).
CLI::Option* addNumber(CLI::App* cmd, const std::string& name, double& value, const io::Range& range,
                       const std::string& help);
// Seconds in `range` that also convert to Time without overflow (|s| <= io::kMaxSeconds); kept in seconds.
CLI::Option* addSeconds(CLI::App* cmd, const std::string& name, double& seconds, const io::Range& range,
                        const std::string& help);
// A rate [Hz] in (0, max_hz].
CLI::Option* addRate(CLI::App* cmd, const std::string& name, double& hz, double max_hz, const std::string& help);
// An integer in [min, max], parsed exactly (no wrap-around of "-1" or 2^70).
template <typename Int>
CLI::Option* addInteger(CLI::App* cmd, const std::string& name, Int& value, std::int64_t min, std::int64_t max,
                        const std::string& help) {
  return cmd->add_option_function<std::string>(
      name,
      [&value, name, min, max](const std::string& text) {
        value = static_cast<Int>(io::parseInteger(text, min, max, io::ValueSource::option(name)));
      },
      help);
}
// A random seed in [0, 2^64 - 1].
CLI::Option* addSeed(CLI::App* cmd, const std::string& name, std::uint64_t& seed, const std::string& help);

using io::atLeast;
using io::between;
using io::positive;

}  // namespace drover::cli
