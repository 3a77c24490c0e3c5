// drover features: keypoint detection and tracking on images and datasets (the VIS front end). The subcommands
// live in cmd_features_detect.cpp and cmd_features_track.cpp.
#include "apps/drover/commands.hpp"

namespace drover::cli {

void registerFeatures(CLI::App& app) {
  auto* cmd = app.add_subcommand("features", "Visual front end: detect keypoints in images, track them over a dataset");
  cmd->require_subcommand(1);
  registerFeaturesDetect(*cmd);
  registerFeaturesTrack(*cmd);
}

}  // namespace drover::cli
