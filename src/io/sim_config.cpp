// The `sim:` section of a platform config (config/farm_sim.yaml), read for `drover sim --config`.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "io/config.hpp"
#include "io/error.hpp"
#include "io/yaml_section.hpp"
#include "io/sim_dataset.hpp"
#include "io/text_parsing.hpp"
#include "io/user_values.hpp"

namespace drover::io {
namespace {

std::string keyRecord(const YAML::Node& n, const std::string& key) {
  const int line = n.Mark().line;
  return (line >= 0 ? lineRecord(static_cast<std::size_t>(line + 1)) + ", " : std::string()) + "key " +
         echo("sim." + key);
}

std::string scalar(const YAML::Node& n, const std::string& key, const std::string& file) {
  if (!n.IsScalar()) fail(file, keyRecord(n, key), "expected a single value");
  return n.Scalar();
}

ValueSource source(const YAML::Node& n, const std::string& key, const std::string& file) {
  return {file, keyRecord(n, key)};
}

// A rate key [Hz], checked as `drover sim`'s options are (io/user_values.hpp).
double rate(const YAML::Node& n, const std::string& key, const std::string& file, double max_hz) {
  const ValueSource src = source(n, key, file);
  return checkedRate(parseNumber(scalar(n, key, file), src), max_hz, src);
}

bool boolean(const YAML::Node& n, const std::string& key, const std::string& file) {
  bool v = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
    fail(file, keyRecord(n, key), "expected true or false");
  return v;
}

void readKey(const YAML::Node& n, const std::string& key, const std::string& file, SimConfigSettings& s) {
  if (key == "rig") {
    const std::string r = scalar(n, key, file);
    if (r != "robot" && r != "euroc")
      fail(file, keyRecord(n, key), "unknown rig " + echo(r) + " (expected robot or euroc)");
    s.rig = r;
  } else if (key == "lidar_model") {
    const std::string m = scalar(n, key, file);
    if (m != "vlp16" && m != "vlp32" && m != "hdl64")
      fail(file, keyRecord(n, key), "unknown lidar " + echo(m) + " (expected vlp16, vlp32 or hdl64)");
    s.lidar_model = m;
  } else if (key == "lidar_columns") {
    s.lidar_columns = static_cast<int>(parseInteger(scalar(n, key, file), 1, 100000, source(n, key, file)));
  } else if (key == "camera_pixel_samples") {
    s.camera_pixel_samples = static_cast<int>(parseInteger(scalar(n, key, file), 1, 4, source(n, key, file)));
  } else if (key == "lidar_time_offset" || key == "camera_time_offset") {
    Range r{-kMaxSimTimeOffsetS, kMaxSimTimeOffsetS};
    r.unit = "s";
    const double v = parseNumber(scalar(n, key, file), source(n, key, file));
    checkedSeconds(v, r, source(n, key, file));
    (key == "lidar_time_offset" ? s.lidar_time_offset_s : s.camera_time_offset_s) = v;
  } else if (key == "camera_color") {
    s.camera_color = boolean(n, key, file);
  } else if (key == "camera_texture_filter") {
    s.camera_texture_filter = boolean(n, key, file);
  } else if (key == "camera_edge_pixel_samples") {
    s.camera_edge_pixel_samples = static_cast<int>(parseInteger(scalar(n, key, file), 0, 4, source(n, key, file)));
  } else if (key == "noise") {
    s.noise = boolean(n, key, file);
  } else if (key == "ground_truth_rate_hz") {
    Range r{kMinSimGroundTruthRateHz, kMaxSimGroundTruthRateHz};
    r.unit = "Hz";
    s.ground_truth_rate_hz = parseNumber(scalar(n, key, file), r, source(n, key, file));
  } else if (key == "lidar_rate_hz") {
    s.lidar_rate_hz = rate(n, key, file, kMaxSimLidarRateHz);
  } else if (key == "camera_rate_hz") {
    s.camera_rate_hz = rate(n, key, file, kMaxSimCameraRateHz);
  } else {
    s.imu_rate_hz = rate(n, key, file, kMaxSimImuRateHz);  // the only key left of `known`
  }
}

}  // namespace

SimConfigSettings loadSimConfigSettings(const std::string& yaml_path) {
  const YAML::Node root = loadConfigRoot(yaml_path);
  SimConfigSettings s;
  if (root.IsNull()) return s;
  const YAML::Node sim = root["sim"];
  if (!sim || sim.IsNull()) return s;
  if (!sim.IsMap()) fail(yaml_path, "key 'sim'", "expected a map of settings");
  static const std::vector<std::string> known = {
      "lidar_model",    "lidar_rate_hz", "lidar_columns",        "camera_rate_hz",    "camera_color",
      "imu_rate_hz",    "noise",         "ground_truth_rate_hz", "lidar_time_offset", "camera_time_offset",
      "camera_pixel_samples", "camera_texture_filter", "camera_edge_pixel_samples", "rig"};
  for (const auto& kv : sim) {
    const std::string key = kv.first.Scalar();
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      fail(yaml_path, keyRecord(kv.first, key), "unknown key (expected one of: " + list + ")");
    }
    readKey(kv.second, key, yaml_path, s);
  }
  // Edge rays refine a pixel whose first rays disagree: there must be several first rays, and fewer.
  const int first = s.camera_pixel_samples.value_or(1), edge = s.camera_edge_pixel_samples.value_or(0);
  if (edge > 0 && (first < 2 || edge <= first)) {
    fail(yaml_path, "key 'sim.camera_edge_pixel_samples'",
         "must be 0 (off) or more than sim.camera_pixel_samples (" + std::to_string(first) +
             "), which must then be at least 2; got " + std::to_string(edge));
  }
  return s;
}

}  // namespace drover::io
