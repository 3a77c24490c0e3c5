// drover features track: placeholder until it lands.
#include "apps/drover/commands.hpp"

namespace drover::cli {

void registerFeaturesTrack(CLI::App& features) { features.add_subcommand("track", "not built yet"); }

}  // namespace drover::cli
