#include "io/visual/visual_config_io.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "io/config.hpp"
#include "io/error.hpp"
#include "io/text_parsing.hpp"
#include "io/user_values.hpp"
#include "io/yaml_section.hpp"

namespace drover::io {
namespace {

void bindShiTomasi(YamlSection& s, visual::ShiTomasiConfig& c) {
  s.bind("max_cnt", c.max_cnt)
      .bind("min_dist", c.min_dist)
      .bind("quality_level", c.quality_level)
      .bind("block_size", c.block_size);
}

void bindOrb(YamlSection& s, visual::OrbConfig& c) {
  s.bind("n_features", c.n_features)
      .bind("scale_factor", c.scale_factor)
      .bind("n_levels", c.n_levels)
      .bind("fast_threshold", c.fast_threshold)
      .bind("edge_threshold", c.edge_threshold);
}

void bindSuperPoint(YamlSection& s, visual::SuperPointConfig& c) {
  s.bind("weights", c.weights)
      .bind("input_width", c.input_width)
      .bind("input_height", c.input_height)
      .bind("max_keypoints", c.max_keypoints)
      .bind("confidence_threshold", c.post.confidence_threshold)
      .bind("nms_radius", c.post.nms_radius)
      .bind("border", c.post.border)
      .bind("min_keypoints", c.post.min_keypoints)
      .bind("grid_cols", c.post.grid_cols)
      .bind("grid_rows", c.post.grid_rows)
      .bind("threads", c.threads);
}

void bindDetector(YamlSection& s, visual::DetectorConfig& c, std::string& type) {
  s.bindChoice("type", type, {"superpoint", "shi-tomasi", "orb"})
      .nested("shi_tomasi", [&](YamlSection& n) { bindShiTomasi(n, c.shi_tomasi); })
      .nested("orb", [&](YamlSection& n) { bindOrb(n, c.orb); })
      .nested("superpoint", [&](YamlSection& n) { bindSuperPoint(n, c.superpoint); });
}

void bindTracker(YamlSection& s, visual::FeatureTrackerConfig& c, std::string& clahe) {
  s.bind("max_features", c.max_features)
      .bind("min_distance", c.min_distance)
      .bind("flow_window", c.flow_window)
      .bind("flow_levels", c.flow_levels)
      .bind("flow_iterations", c.flow_iterations)
      .bind("flow_epsilon", c.flow_epsilon)
      .bind("min_eigenvalue", c.min_eigenvalue)
      .bind("forward_backward", c.forward_backward)
      .bind("forward_backward_px", c.forward_backward_px)
      .bind("border_px", c.border_px)
      .bind("ransac", c.ransac)
      .bind("ransac_threshold_px", c.ransac_threshold_px)
      .bind("ransac_confidence", c.ransac_confidence)
      .bind("virtual_focal_px", c.virtual_focal_px)
      .bindChoice("clahe", clahe, {"off", "always", "when_dark"})
      .bind("clahe_clip", c.clahe_clip)
      .bind("clahe_tiles", c.clahe_tiles)
      .bind("dark_mean", c.dark_mean)
      .bind("async_detection", c.async_detection)
      .bind("detect_below", c.detect_below)
      .bind("detect_interval_s", c.detect_interval_s)
      .bind("detect_urgent_below", c.detect_urgent_below)
      .bind("detect_sync_below", c.detect_sync_below)
      .bind("top_up_below", c.top_up_below)
      .bind("top_up_min_eigenvalue", c.top_up_min_eigenvalue);
}

void bindDepth(YamlSection& s, visual::DepthAssociationConfig& c) {
  s.bindSeconds("window_s", c.window_s, positive("s"))
      .bind("voxel_size", c.voxel_size)
      .bind("grid_resolution_deg", c.grid_resolution_deg)
      .bind("neighbour_cells", c.neighbour_cells)
      .bind("max_depth_spread", c.max_depth_spread)
      .bind("min_depth", c.min_depth)
      .bind("max_depth", c.max_depth)
      .bind("min_incidence_cos", c.min_incidence_cos);
}

const char* claheName(visual::ClaheMode m) {
  switch (m) {
    case visual::ClaheMode::kOff:
      return "off";
    case visual::ClaheMode::kAlways:
      return "always";
    case visual::ClaheMode::kWhenDark:
      break;
  }
  return "when_dark";
}

visual::ClaheMode parseClahe(const std::string& name) {  // already checked by bindChoice
  if (name == "off") return visual::ClaheMode::kOff;
  if (name == "always") return visual::ClaheMode::kAlways;
  return visual::ClaheMode::kWhenDark;
}

// A relative weights path is the working directory's (the shipped configs' ../shared/... is the repository root's).
// Where nothing is there but the file sits beside the config, that is the one meant: a platform file kept with its
// own weights then works from any working directory; after it the caller's folders. Otherwise the path is left as
// written, for the detector's error to name.
std::string resolveWeights(const std::string& yaml_path, const std::string& path,
                           const std::vector<std::string>& also_look_in) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path p(path);
  if (path.empty() || p.is_absolute() || fs::exists(p, ec)) return path;
  std::vector<fs::path> folders{fs::path(yaml_path).parent_path()};
  folders.insert(folders.end(), also_look_in.begin(), also_look_in.end());
  for (const fs::path& folder : folders) {
    const fs::path there = folder / p;
    if (fs::is_regular_file(there, ec)) return there.lexically_normal().string();
  }
  return path;
}

}  // namespace

VisualConfig loadVisualConfig(const std::string& yaml_path, const std::vector<std::string>& also_look_in) {
  const YAML::Node root = loadConfigRoot(yaml_path);
  VisualConfig c;
  if (root.IsNull()) return c;
  std::string type = visual::detectorTypeName(c.detector.type);
  std::string clahe = claheName(c.tracker.clahe);
  YamlSection top(yaml_path, "visual");
  top.nested("detector", [&](YamlSection& s) { bindDetector(s, c.detector, type); })
      .nested("tracker", [&](YamlSection& s) { bindTracker(s, c.tracker, clahe); })
      .nested("depth", [&](YamlSection& s) { bindDepth(s, c.depth); });
  const YAML::Node visual = root["visual"];
  top.apply(visual);
  c.detector.type = visual::parseDetectorType(type);  // already checked by bindChoice
  c.tracker.clahe = parseClahe(clahe);
  c.detector.superpoint.weights = resolveWeights(yaml_path, c.detector.superpoint.weights, also_look_in);
  // Every detector's settings are checked, not only the chosen one's: a typo must not wait for a switch.
  const YAML::Node det = visual && visual.IsMap() ? visual["detector"] : YAML::Node();
  auto sub = [&](const char* key) { return det && det.IsMap() ? det[key] : YAML::Node(); };
  checkSectionValid(yaml_path, sub("shi_tomasi"), "visual.detector.shi_tomasi", c.detector.shi_tomasi.validate());
  checkSectionValid(yaml_path, sub("orb"), "visual.detector.orb", c.detector.orb.validate());
  checkSectionValid(yaml_path, sub("superpoint"), "visual.detector.superpoint", c.detector.superpoint.validate());
  auto section = [&](const char* key) { return visual && visual.IsMap() ? visual[key] : YAML::Node(); };
  checkSectionValid(yaml_path, section("tracker"), "visual.tracker", c.tracker.validate());
  checkSectionValid(yaml_path, section("depth"), "visual.depth", c.depth.validate());
  return c;
}

}  // namespace drover::io
