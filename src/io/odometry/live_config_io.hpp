#pragma once
// The `live:` section of a platform config -> pipeline::LiveConfig, for the live system (drover run --realtime, the
// ROS node). Keys, all optional (defaults and units in pipeline/system.hpp):
//   live: sweep_queue [sweeps], frame_queue [frames], loop_rate_hz [Hz]
#include <string>

#include "pipeline/system.hpp"

namespace drover::io {

// Throws IoError (file, line, key) for a missing file, invalid YAML, unknown key or bad value.
pipeline::LiveConfig loadLiveConfig(const std::string& yaml_path);

}  // namespace drover::io
