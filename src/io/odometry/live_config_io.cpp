#include "io/odometry/live_config_io.hpp"

#include <yaml-cpp/yaml.h>

#include "io/yaml_section.hpp"

namespace drover::io {

pipeline::LiveConfig loadLiveConfig(const std::string& yaml_path) {
  const YAML::Node root = loadConfigRoot(yaml_path);
  pipeline::LiveConfig c;
  if (root.IsNull()) return c;
  YamlSection live(yaml_path, "live");
  live.bind("sweep_queue", c.sweep_queue).bind("frame_queue", c.frame_queue).bind("loop_rate_hz", c.loop_rate_hz);
  live.bind("clock_jump_s", c.clock_jump_s).bind("sensor_gap_s", c.sensor_gap_s);
  const YAML::Node node = root["live"];
  live.apply(node);
  checkSectionValid(yaml_path, node, "live", c.validate());
  return c;
}

}  // namespace drover::io
