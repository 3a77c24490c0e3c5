// drover features detect: run one keypoint detector (SuperPoint, Shi-Tomasi or ORB) on image files and report,
// per image, the keypoint count, the coverage (fraction of a 16 x 12 grid of cells holding a keypoint) and the
// detection time; optionally as JSON and as images with the keypoints drawn.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/drover/checked_options.hpp"
#include "apps/drover/commands.hpp"
#include "io/error.hpp"
#include "io/image_file_io.hpp"
#include "io/output_paths.hpp"
#include "io/trajectory_io.hpp"
#include "io/user_values.hpp"
#include "io/visual/visual_config_io.hpp"
#include "visual/detector_factory.hpp"
#include "visual/image_darkening.hpp"
#include "visual/keypoint_coverage.hpp"

namespace drover::cli {
namespace {

using Json = nlohmann::ordered_json;

struct DetectOptions {
  std::vector<std::string> images;
  std::string detector, config, weights, json, draw, input_size;
  int max = -1;       // -1 = the detector's own cap
  double darken = 0;  // 0 = off; else the exposure factor (visual/image_darkening.hpp)
  std::uint64_t seed = 1;
  bool json_points = false;  // also write every keypoint's [x, y] to the JSON
};

visual::DetectorConfig detectorConfig(const DetectOptions& o) {
  visual::DetectorConfig c = o.config.empty() ? visual::DetectorConfig{} : io::loadVisualConfig(o.config).detector;
  if (!o.detector.empty()) c.type = visual::parseDetectorType(o.detector);
  if (!o.weights.empty()) c.superpoint.weights = o.weights;
  if (!o.input_size.empty()) {
    const io::ValueSource source = io::ValueSource::option("--input-size");
    const std::size_t x = o.input_size.find('x');
    if (x == std::string::npos) io::failValue(source, "expected WxH (e.g. 640x480), got " + io::echo(o.input_size));
    // [px] each side; validate() below asks for multiples of 8.
    c.superpoint.input_width = static_cast<int>(io::parseInteger(o.input_size.substr(0, x), 8, 16384, source));
    c.superpoint.input_height = static_cast<int>(io::parseInteger(o.input_size.substr(x + 1), 8, 16384, source));
  }
  if (std::string err = c.validate(); !err.empty()) throw std::invalid_argument(err);
  return c;
}

Json settingsJson(const visual::DetectorConfig& c) {
  switch (c.type) {
    case visual::DetectorType::kShiTomasi:
      return {{"max_cnt", c.shi_tomasi.max_cnt},
              {"min_dist", c.shi_tomasi.min_dist},
              {"quality_level", c.shi_tomasi.quality_level},
              {"block_size", c.shi_tomasi.block_size}};
    case visual::DetectorType::kOrb:
      return {{"n_features", c.orb.n_features},
              {"scale_factor", c.orb.scale_factor},
              {"n_levels", c.orb.n_levels},
              {"fast_threshold", c.orb.fast_threshold},
              {"edge_threshold", c.orb.edge_threshold}};
    case visual::DetectorType::kSuperPoint:
      return {{"weights", c.superpoint.weights},
              {"input_width", c.superpoint.input_width},
              {"input_height", c.superpoint.input_height},
              {"max_keypoints", c.superpoint.max_keypoints},
              {"confidence_threshold", c.superpoint.post.confidence_threshold},
              {"nms_radius", c.superpoint.post.nms_radius},
              {"border", c.superpoint.post.border}};
  }
  return {};
}

// OUT.png for one image; OUT_<index>.png (index from 0, in the order given) for several.
std::string drawPath(const std::string& draw, std::size_t index, std::size_t n) {
  if (n == 1) return draw;
  const std::filesystem::path p(draw);
  return (p.parent_path() / (p.stem().string() + "_" + std::to_string(index) + p.extension().string())).string();
}

void drawKeypoints(const std::string& path, const cv::Mat& grey, const visual::Keypoints& k) {
  cv::Mat colour;
  cv::cvtColor(grey, colour, cv::COLOR_GRAY2BGR);
  for (const cv::Point2f& p : k.points) cv::circle(colour, p, 3, cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
  io::writeImage(path, colour);
}

void runDetect(const DetectOptions& o) {
  io::checkOutputFile(o.json, "--json");
  if (!o.draw.empty())
    for (std::size_t i = 0; i < o.images.size(); ++i)
      io::checkOutputFile(drawPath(o.draw, i, o.images.size()), "--draw");
  const visual::DetectorConfig cfg = detectorConfig(o);
  const std::unique_ptr<visual::KeypointDetector> detector = visual::makeDetector(cfg);
  Json images = Json::array();
  double total_ms = 0, total_cov = 0;
  for (std::size_t i = 0; i < o.images.size(); ++i) {
    cv::Mat image = io::readGreyImage(o.images[i]);
    if (o.darken > 0) {
      visual::DarkeningConfig dark;
      dark.scale = o.darken;
      dark.seed = o.seed + i;
      image = visual::darkenImage(image, dark);
    }
    const auto t0 = std::chrono::steady_clock::now();
    const visual::Keypoints k = detector->detect(image, cv::Mat(), o.max < 0 ? std::numeric_limits<int>::max() : o.max);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const double coverage = visual::gridCoverage(k.points, image.size());
    total_ms += ms;
    total_cov += coverage;
    spdlog::info("{}: {} keypoints, coverage {:.3f}, {:.1f} ms", o.images[i], k.points.size(), coverage, ms);
    Json entry = {{"path", o.images[i]},
                  {"count", k.points.size()},
                  {"coverage", coverage},
                  {"ms", ms},
                  {"mean_intensity", cv::mean(image)[0]}};
    if (o.json_points) {
      Json pts = Json::array();
      for (const cv::Point2f& p : k.points) pts.push_back({p.x, p.y});
      entry["points"] = std::move(pts);
    }
    images.push_back(std::move(entry));
    if (!o.draw.empty()) drawKeypoints(drawPath(o.draw, i, o.images.size()), image, k);
  }
  const double n = static_cast<double>(o.images.size());
  spdlog::info("{}: {} images, mean coverage {:.3f}, mean {:.1f} ms per image", detector->name(), o.images.size(),
               total_cov / n, total_ms / n);
  if (o.json.empty()) return;
  Json j = {{"detector", detector->name()}, {"settings", settingsJson(cfg)}};
  if (o.darken > 0) j["darken"] = {{"scale", o.darken}, {"shot_gain", 1.0}, {"read_sigma", 2.0}, {"seed", o.seed}};
  j["images"] = images;
  io::writeFileAtomically(o.json, j.dump(2) + "\n");
}

}  // namespace

void registerFeaturesDetect(CLI::App& features) {
  auto o = std::make_shared<DetectOptions>();
  auto* cmd =
      features.add_subcommand("detect", "Detect keypoints in images: count, coverage of a 16x12 grid, ms per image");
  cmd->add_option("images", o->images, "Image files (8/16-bit, grey or colour; converted to 8-bit grey)")->required();
  cmd->add_option("--detector", o->detector, "superpoint | shi-tomasi | orb (default: the config's, else superpoint)")
      ->check(CLI::IsMember({"superpoint", "shi-tomasi", "orb"}));
  cmd->add_option("--config", o->config, "Platform config: its visual.detector section (config/*.yaml)");
  cmd->add_option("--weights", o->weights,
                  "SuperPoint ONNX weights (default ../shared/models/superpoint_v1.onnx: MagicLeap, non-commercial)");
  cmd->add_option("--input-size", o->input_size, "SuperPoint network input WxH, multiples of 8 (default: the image)");
  addInteger(cmd, "--max", o->max, 1, 1'000'000, "At most N keypoints per image, N >= 1 (default: the detector's cap)");
  cmd->add_option("--json", o->json,
                  "Also write {detector, settings, images: [{path, count, coverage, ms, mean_intensity}]}");
  cmd->add_flag("--json-points", o->json_points, "Also write each image's keypoints [[x, y], ...] to the JSON");
  cmd->add_option("--draw", o->draw, "Write the image with its keypoints (several images: OUT_<index>.png)");
  io::Range exposure{0, 1};
  exposure.min_open = true;
  addNumber(cmd, "--darken", o->darken, exposure,
            "Detect on a darkened copy: exposure x SCALE in (0, 1], shot noise (1 grey level/e-) and read noise "
            "(sigma 2 grey levels)");
  addSeed(cmd, "--seed", o->seed, "Noise seed for --darken in [0, 2^64 - 1] (image i uses seed + i)");
  cmd->callback([o] { runDetect(*o); });
}

}  // namespace drover::cli
