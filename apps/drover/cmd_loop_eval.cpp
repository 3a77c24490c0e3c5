// drover loop eval: placeholder.
#include "apps/drover/commands.hpp"

namespace drover::cli {

void registerLoopEval(CLI::App& loop) { loop.add_subcommand("eval", "not built yet"); }

}  // namespace drover::cli
