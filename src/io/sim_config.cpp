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

namespace drover::io {
namespace {

std::string keyRecord(const YAML::Node& n, const std::string& key) {
  const int line = n.Mark().line;
  return (line >= 0 ? lineRecord(static_cast<std::size_t>(line + 1)) + ", " : std::string()) + "key 'sim." + key +
         "'";
}

std::string scalar(const YAML::Node& n, const std::string& key, const std::string& file) {
  if (!n.IsScalar()) fail(file, keyRecord(n, key), "expected a single value");
  return n.Scalar();
}

double positiveNumber(const YAML::Node& n, const std::string& key, const std::string& file) {
  const double v = parseDouble(scalar(n, key, file), file, keyRecord(n, key));
  if (!(v > 0)) fail(file, keyRecord(n, key), "must be positive");
  return v;
}

bool boolean(const YAML::Node& n, const std::string& key, const std::string& file) {
  bool v = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
    fail(file, keyRecord(n, key), "expected true or false");
  return v;
}

void readKey(const YAML::Node& n, const std::string& key, const std::string& file, SimConfigSettings& s) {
  if (key == "lidar_model") {
    const std::string m = scalar(n, key, file);
    if (m != "vlp16" && m != "vlp32" && m != "hdl64")
      fail(file, keyRecord(n, key), "unknown lidar '" + m + "' (expected vlp16, vlp32 or hdl64)");
    s.lidar_model = m;
  } else if (key == "lidar_columns") {
    const std::int64_t c = parseInt64(scalar(n, key, file), file, keyRecord(n, key));
    if (c < 1 || c > 100000) fail(file, keyRecord(n, key), "expected 1..100000 columns");
    s.lidar_columns = static_cast<int>(c);
  } else if (key == "lidar_time_offset" || key == "camera_time_offset") {
    const double v = parseDouble(scalar(n, key, file), file, keyRecord(n, key));
    if (std::abs(v) > 1.0) fail(file, keyRecord(n, key), "time offset beyond one second");
    (key == "lidar_time_offset" ? s.lidar_time_offset_s : s.camera_time_offset_s) = v;
  } else if (key == "camera_color") {
    s.camera_color = boolean(n, key, file);
  } else if (key == "noise") {
    s.noise = boolean(n, key, file);
  } else if (key == "ground_truth_rate_hz") {
    s.ground_truth_rate_hz = positiveNumber(n, key, file);
    if (*s.ground_truth_rate_hz < 100) fail(file, keyRecord(n, key), "must be >= 100 Hz");
  } else {
    const double v = positiveNumber(n, key, file);
    if (key == "lidar_rate_hz") {
      s.lidar_rate_hz = v;
    } else if (key == "camera_rate_hz") {
      s.camera_rate_hz = v;
    } else {
      s.imu_rate_hz = v;  // the only key left of `known`
    }
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
      "imu_rate_hz",    "noise",         "ground_truth_rate_hz", "lidar_time_offset", "camera_time_offset"};
  for (const auto& kv : sim) {
    const std::string key = kv.first.Scalar();
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      fail(yaml_path, keyRecord(kv.first, key), "unknown key (expected one of: " + list + ")");
    }
    readKey(kv.second, key, yaml_path, s);
  }
  return s;
}

}  // namespace drover::io
