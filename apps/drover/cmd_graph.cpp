// drover graph: placeholder until the subcommands land.
#include "apps/drover/commands.hpp"

namespace drover::cli {

void registerGraph(CLI::App& app) { app.add_subcommand("graph", "Pose-graph tools (optimize): not built yet"); }

}  // namespace drover::cli
