#pragma once
// Each subcommand lives in its own cmd_<name>.cpp and registers itself on the root app.
// A command's callback throws on error; main() turns any exception into one line and exit code 2.
#include <CLI/CLI.hpp>

namespace drover::cli {

void registerEval(CLI::App& app);
void registerInfo(CLI::App& app);
void registerSim(CLI::App& app);
void registerRun(CLI::App& app);

}  // namespace drover::cli
