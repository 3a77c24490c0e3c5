#include "apps/drover/checked_options.hpp"

namespace drover::cli {

CLI::Option* addNumber(CLI::App* cmd, const std::string& name, double& value, const io::Range& range,
                       const std::string& help) {
  return cmd->add_option_function<std::string>(
      name,
      [&value, name, range](const std::string& text) {
        value = io::parseNumber(text, range, io::ValueSource::option(name));
      },
      help);
}

CLI::Option* addSeconds(CLI::App* cmd, const std::string& name, double& seconds, const io::Range& range,
                        const std::string& help) {
  return cmd->add_option_function<std::string>(
      name,
      [&seconds, name, range](const std::string& text) {
        const io::ValueSource source = io::ValueSource::option(name);
        seconds = io::parseNumber(text, source);
        io::checkedSeconds(seconds, range, source);
      },
      help);
}

CLI::Option* addRate(CLI::App* cmd, const std::string& name, double& hz, double max_hz, const std::string& help) {
  return cmd->add_option_function<std::string>(
      name,
      [&hz, name, max_hz](const std::string& text) {
        const io::ValueSource source = io::ValueSource::option(name);
        hz = io::checkedRate(io::parseNumber(text, source), max_hz, source);
      },
      help);
}

CLI::Option* addSeed(CLI::App* cmd, const std::string& name, std::uint64_t& seed, const std::string& help) {
  return cmd->add_option_function<std::string>(
      name, [&seed, name](const std::string& text) { seed = io::parseSeed(text, io::ValueSource::option(name)); },
      help);
}

}  // namespace drover::cli
