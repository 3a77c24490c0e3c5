// drover: the command line. Thin by design: parsing, progress and exit codes; the work is in the libraries.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <exception>

#include "apps/drover/commands.hpp"
#include "apps/drover/heap_tuning.hpp"

int main(int argc, char** argv) {
  drover::cli::tuneHeapForSweeps();
  CLI::App app{"Drover: lidar-visual-inertial SLAM for mobile robots in hard places"};
  app.require_subcommand(1);
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (const drover::cli::ExitCode& e) {
    return e.code;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  return 0;
}
