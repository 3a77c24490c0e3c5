#include "io/visual/visual_config_io.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "io/config.hpp"
#include "io/error.hpp"
#include "io/text_parsing.hpp"
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
      .bind("threads", c.threads);
}

void bindDetector(YamlSection& s, visual::DetectorConfig& c, std::string& type) {
  s.bindChoice("type", type, {"superpoint", "shi-tomasi", "orb"})
      .nested("shi_tomasi", [&](YamlSection& n) { bindShiTomasi(n, c.shi_tomasi); })
      .nested("orb", [&](YamlSection& n) { bindOrb(n, c.orb); })
      .nested("superpoint", [&](YamlSection& n) { bindSuperPoint(n, c.superpoint); });
}

// A Config::validate() message, with the line of the sub-section it concerns when the file has one.
void checkValid(const std::string& file, const YAML::Node& node, const std::string& section, const std::string& err) {
  if (err.empty()) return;
  const int line = node ? node.Mark().line : -1;
  fail(
      file,
      (line >= 0 ? lineRecord(static_cast<std::size_t>(line + 1)) + ", " : std::string()) + "section '" + section + "'",
      err);
}

}  // namespace

VisualConfig loadVisualConfig(const std::string& yaml_path) {
  if (!std::filesystem::exists(yaml_path)) fail(yaml_path, "", "config file not found");
  YAML::Node root;
  try {
    root = YAML::Load(readYamlText(yaml_path));
  } catch (const YAML::Exception& e) {
    fail(yaml_path, lineRecord(static_cast<std::size_t>(e.mark.line + 1)), "invalid YAML: " + e.msg);
  }
  VisualConfig c;
  if (root.IsNull()) return c;
  if (!root.IsMap()) fail(yaml_path, "", "expected a YAML map of sections at top level");
  std::string type = visual::detectorTypeName(c.detector.type);
  YamlSection top(yaml_path, "visual");
  top.nested("detector", [&](YamlSection& s) { bindDetector(s, c.detector, type); });
  const YAML::Node visual = root["visual"];
  top.apply(visual);
  c.detector.type = visual::parseDetectorType(type);  // already checked by bindChoice
  // Every detector's settings are checked, not only the chosen one's: a typo must not wait for a switch.
  const YAML::Node det = visual && visual.IsMap() ? visual["detector"] : YAML::Node();
  auto sub = [&](const char* key) { return det && det.IsMap() ? det[key] : YAML::Node(); };
  checkValid(yaml_path, sub("shi_tomasi"), "visual.detector.shi_tomasi", c.detector.shi_tomasi.validate());
  checkValid(yaml_path, sub("orb"), "visual.detector.orb", c.detector.orb.validate());
  checkValid(yaml_path, sub("superpoint"), "visual.detector.superpoint", c.detector.superpoint.validate());
  return c;
}

}  // namespace drover::io
