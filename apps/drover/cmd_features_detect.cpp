// drover features detect: placeholder until it lands.
#include "apps/drover/commands.hpp"

namespace drover::cli {

void registerFeaturesDetect(CLI::App& features) { features.add_subcommand("detect", "not built yet"); }

}  // namespace drover::cli
