// drover: the command line. Thin by design: parsing, progress and exit codes; the work is in the libraries.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <exception>
#include <string>

#include "apps/drover/commands.hpp"
#include "apps/drover/heap_tuning.hpp"
#include "io/error.hpp"

namespace {

// CLI11's own message (bad choice, unknown argument, missing option) as one short line: it may quote a value the
// user typed, which can be megabytes long or hold line breaks.
std::string oneShortLine(const std::string& message) {
  constexpr std::size_t kMax = 200;  // [characters]
  std::string out;
  for (std::size_t i = 0; i < message.size() && i < kMax; ++i) out += message[i] == '\n' ? ' ' : message[i];
  if (message.size() > kMax) out += "... (" + std::to_string(message.size()) + " characters)";
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  drover::cli::tuneHeapForSweeps();
  CLI::App app{"Drover: lidar-visual-inertial SLAM for mobile robots in hard places"};
  app.require_subcommand(1);
  // Inherited by every subcommand made after this: an option a subcommand does not know (-q) goes to its parent,
  // so `-q` works after any command.
  app.fallthrough();
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "Only print errors");
  app.parse_complete_callback([&] { spdlog::set_level(quiet ? spdlog::level::err : spdlog::level::info); });
  spdlog::set_pattern("%^[%l]%$ %v");
  drover::cli::registerEval(app);
  drover::cli::registerInfo(app);
  drover::cli::registerSim(app);
  drover::cli::registerRun(app);
  drover::cli::registerLoop(app);
  drover::cli::registerGraph(app);
  drover::cli::registerFeatures(app);
  drover::cli::registerConfig(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    spdlog::error("{} (drover --help lists the commands and options)", oneShortLine(e.what()));
    return 2;
  } catch (const drover::cli::ExitCode& e) {
    return e.code;
  } catch (const std::exception& e) {
    spdlog::error("{}", drover::io::boundedText(e.what(), 2000));  // any message stays one line of bounded length
    return 2;
  }
  return 0;
}
