// drover loop: placeholder until the subcommands land.
#include "apps/drover/commands.hpp"

namespace drover::cli {

void registerLoop(CLI::App& app) { app.add_subcommand("loop", "Loop closure tools (pair, eval): not built yet"); }

}  // namespace drover::cli
