#include "apps/drover/commands.hpp"

namespace drover::cli {
void registerInfo(CLI::App& app) { app.add_subcommand("info", "Summarise a dataset's measurement stream"); }
}  // namespace drover::cli
