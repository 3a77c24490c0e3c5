#include "apps/drover/commands.hpp"

namespace drover::cli {
void registerEval(CLI::App& app) { app.add_subcommand("eval", "Evaluate a trajectory against ground truth"); }
}  // namespace drover::cli
