// The `visual:` section of a platform config -> io::VisualConfig (io/visual/visual_config_io.hpp): the shipped
// configs load, every key reaches its own field, and every mistake is an IoError naming the file, the line and the
// dotted key. (In tests/cli because that test module links drover_io_visual.)
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "io/error.hpp"
#include "io/visual/visual_config_io.hpp"
#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

using visual::DetectorType;

VisualConfig loadVisual(const test::TempDir& dir, const std::string& text) {
  const auto path = dir / "visual.yaml";
  test::writeText(path, text);
  return loadVisualConfig(path.string());
}

std::string visualErrorOf(const test::TempDir& dir, const std::string& text) {
  try {
    loadVisual(dir, text);
  } catch (const IoError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an IoError for:\n" << text;
  return {};
}

bool hasPart(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(VisualConfigReader, ShippedConfigsChooseSuperPointWithTheSharedWeights) {
  for (const char* name : {"kitti.yaml", "euroc.yaml", "farm_sim.yaml"}) {
    SCOPED_TRACE(name);
    VisualConfig c;
    ASSERT_NO_THROW(c = loadVisualConfig(test::config(name)));
    EXPECT_EQ(c.detector.type, DetectorType::kSuperPoint);
    EXPECT_EQ(c.detector.superpoint.weights, "../shared/models/superpoint_v1.onnx");
    EXPECT_EQ(c.detector.validate(), "");
  }
  EXPECT_DOUBLE_EQ(loadVisualConfig(test::config("euroc.yaml")).detector.shi_tomasi.min_dist, 30.0);
  EXPECT_EQ(loadVisualConfig(test::config("kitti.yaml")).detector.shi_tomasi.max_cnt, 200);
}

TEST(VisualConfigReader, AFileWithoutAVisualSectionGivesTheDefaults) {
  test::TempDir dir;
  const VisualConfig c = loadVisual(dir, "dataset:\n  load_images: true\n");
  EXPECT_EQ(c.detector.type, DetectorType::kSuperPoint);
  EXPECT_EQ(c.detector.shi_tomasi.max_cnt, visual::ShiTomasiConfig{}.max_cnt);
}

TEST(VisualConfigReader, EveryKeyReachesItsOwnField) {
  test::TempDir dir;
  const VisualConfig c = loadVisual(dir, R"(visual:
  detector:
    type: orb
    shi_tomasi: {max_cnt: 11, min_dist: 12.5, quality_level: 0.013, block_size: 5}
    orb: {n_features: 21, scale_factor: 1.3, n_levels: 4, fast_threshold: 17, edge_threshold: 33}
    superpoint:
      weights: /models/sp.onnx
      input_width: 320
      input_height: 240
      max_keypoints: 31
      confidence_threshold: 0.02
      nms_radius: 3
      border: 6
      threads: 2
      min_keypoints: 40
      grid_cols: 7
      grid_rows: 5
)");
  const visual::DetectorConfig& d = c.detector;
  EXPECT_EQ(d.type, DetectorType::kOrb);
  EXPECT_EQ(d.shi_tomasi.max_cnt, 11);
  EXPECT_DOUBLE_EQ(d.shi_tomasi.min_dist, 12.5);
  EXPECT_DOUBLE_EQ(d.shi_tomasi.quality_level, 0.013);
  EXPECT_EQ(d.shi_tomasi.block_size, 5);
  EXPECT_EQ(d.orb.n_features, 21);
  EXPECT_DOUBLE_EQ(d.orb.scale_factor, 1.3);
  EXPECT_EQ(d.orb.n_levels, 4);
  EXPECT_EQ(d.orb.fast_threshold, 17);
  EXPECT_EQ(d.orb.edge_threshold, 33);
  EXPECT_EQ(d.superpoint.weights, "/models/sp.onnx");
  EXPECT_EQ(d.superpoint.input_width, 320);
  EXPECT_EQ(d.superpoint.input_height, 240);
  EXPECT_EQ(d.superpoint.max_keypoints, 31);
  EXPECT_DOUBLE_EQ(d.superpoint.post.confidence_threshold, 0.02);
  EXPECT_EQ(d.superpoint.post.nms_radius, 3);
  EXPECT_EQ(d.superpoint.post.border, 6);
  EXPECT_EQ(d.superpoint.threads, 2);
  EXPECT_EQ(d.superpoint.post.min_keypoints, 40);
  EXPECT_EQ(d.superpoint.post.grid_cols, 7);
  EXPECT_EQ(d.superpoint.post.grid_rows, 5);
}

TEST(VisualConfigReader, UnknownKeysAndBadValuesNameFileLineAndKey) {
  test::TempDir dir;
  std::string e = visualErrorOf(dir, "visual:\n  detector:\n    superpoint:\n      weigths: x.onnx\n");
  EXPECT_TRUE(hasPart(e, "visual.yaml")) << e;
  EXPECT_TRUE(hasPart(e, "line 4")) << e;
  EXPECT_TRUE(hasPart(e, "visual.detector.superpoint.weigths")) << e;
  e = visualErrorOf(dir, "visual:\n  detector:\n    type: sift\n");
  EXPECT_TRUE(hasPart(e, "line 3")) << e;
  EXPECT_TRUE(hasPart(e, "superpoint, shi-tomasi or orb")) << e;
  e = visualErrorOf(dir, "visual:\n  detector:\n    orb:\n      n_levels: many\n");
  EXPECT_TRUE(hasPart(e, "line 4")) << e;
  EXPECT_TRUE(hasPart(e, "visual.detector.orb.n_levels")) << e;
  e = visualErrorOf(dir, "visual:\n  detectors: {}\n");
  EXPECT_TRUE(hasPart(e, "visual.detectors")) << e;
}

TEST(VisualConfigReader, AGridWithOneSideOrANegativeSideIsRefusedNamingTheSection) {
  test::TempDir dir;
  std::string e = visualErrorOf(dir, "visual:\n  detector:\n    superpoint:\n      grid_cols: 8\n");
  EXPECT_TRUE(hasPart(e, "visual.yaml")) << e;
  EXPECT_TRUE(hasPart(e, "visual.detector.superpoint")) << e;
  EXPECT_TRUE(hasPart(e, "grid_rows")) << e;
  e = visualErrorOf(dir, "visual:\n  detector:\n    superpoint:\n      grid_cols: -8\n      grid_rows: 6\n");
  EXPECT_TRUE(hasPart(e, "must both be >= 1")) << e;
  e = visualErrorOf(dir, "visual:\n  detector:\n    superpoint:\n      grid_rows: six\n");
  EXPECT_TRUE(hasPart(e, "line 4")) << e;
  EXPECT_TRUE(hasPart(e, "visual.detector.superpoint.grid_rows")) << e;
}

TEST(VisualConfigReader, ValuesThatFailValidationNameTheSectionAndItsLine) {
  test::TempDir dir;
  std::string e = visualErrorOf(dir,
                          "visual:\n  detector:\n    type: orb\n    superpoint:\n      input_width: 100\n"
                          "      input_height: 80\n");
  EXPECT_TRUE(hasPart(e, "line 5")) << e;  // yaml-cpp marks a map by its first key
  EXPECT_TRUE(hasPart(e, "visual.detector.superpoint")) << e;
  EXPECT_TRUE(hasPart(e, "multiples of 8")) << e;
  e = visualErrorOf(dir, "visual:\n  detector:\n    shi_tomasi:\n      quality_level: 1.5\n");
  EXPECT_TRUE(hasPart(e, "visual.detector.shi_tomasi")) << e;
  EXPECT_TRUE(hasPart(e, "quality_level")) << e;
  e = visualErrorOf(dir, "visual:\n  detector:\n    orb: {scale_factor: 0.9}\n");
  EXPECT_TRUE(hasPart(e, "line 3")) << e;
  EXPECT_TRUE(hasPart(e, "scale_factor")) << e;
}

TEST(VisualConfigReader, TrackerAndDepthKeysReachTheirFields) {
  test::TempDir dir;
  const VisualConfig c = loadVisual(dir, R"(visual:
  tracker:
    max_features: 40
    min_distance: 12.5
    flow_window: 15
    flow_levels: 2
    flow_iterations: 20
    flow_epsilon: 0.02
    min_eigenvalue: 0.003
    forward_backward: false
    forward_backward_px: 0.75
    border_px: 3
    ransac: false
    ransac_threshold_px: 1.5
    ransac_confidence: 0.95
    virtual_focal_px: 400
    clahe: always
    clahe_clip: 2.5
    clahe_tiles: 4
    dark_mean: 50
    async_detection: true
    detect_interval_s: 0.5
    detect_urgent_below: 30
    detect_sync_below: 12
    top_up_below: 25
    top_up_min_eigenvalue: 0.0002
  depth: {window_s: 3, voxel_size: 0.1, grid_resolution_deg: 1, neighbour_cells: 4, max_depth_spread: 1.5,
          min_depth: 3, max_depth: 80, min_incidence_cos: 0.1}
)");
  const visual::FeatureTrackerConfig& t = c.tracker;
  EXPECT_EQ(t.max_features, 40);
  EXPECT_DOUBLE_EQ(t.min_distance, 12.5);
  EXPECT_EQ(t.flow_window, 15);
  EXPECT_EQ(t.flow_levels, 2);
  EXPECT_EQ(t.flow_iterations, 20);
  EXPECT_DOUBLE_EQ(t.flow_epsilon, 0.02);
  EXPECT_DOUBLE_EQ(t.min_eigenvalue, 0.003);
  EXPECT_FALSE(t.forward_backward);
  EXPECT_DOUBLE_EQ(t.forward_backward_px, 0.75);
  EXPECT_EQ(t.border_px, 3);
  EXPECT_FALSE(t.ransac);
  EXPECT_DOUBLE_EQ(t.ransac_threshold_px, 1.5);
  EXPECT_DOUBLE_EQ(t.ransac_confidence, 0.95);
  EXPECT_DOUBLE_EQ(t.virtual_focal_px, 400);
  EXPECT_EQ(t.clahe, visual::ClaheMode::kAlways);
  EXPECT_DOUBLE_EQ(t.clahe_clip, 2.5);
  EXPECT_EQ(t.clahe_tiles, 4);
  EXPECT_DOUBLE_EQ(t.dark_mean, 50);
  EXPECT_TRUE(t.async_detection);
  EXPECT_DOUBLE_EQ(t.detect_interval_s, 0.5);
  EXPECT_EQ(t.detect_urgent_below, 30);
  EXPECT_EQ(t.detect_sync_below, 12);
  EXPECT_EQ(t.top_up_below, 25);
  EXPECT_DOUBLE_EQ(t.top_up_min_eigenvalue, 2e-4);
  const visual::DepthAssociationConfig& d = c.depth;
  EXPECT_DOUBLE_EQ(d.window_s, 3);
  EXPECT_DOUBLE_EQ(d.voxel_size, 0.1);
  EXPECT_DOUBLE_EQ(d.grid_resolution_deg, 1);
  EXPECT_DOUBLE_EQ(d.neighbour_cells, 4);
  EXPECT_DOUBLE_EQ(d.max_depth_spread, 1.5);
  EXPECT_DOUBLE_EQ(d.min_depth, 3);
  EXPECT_DOUBLE_EQ(d.max_depth, 80);
  EXPECT_DOUBLE_EQ(d.min_incidence_cos, 0.1);
  EXPECT_EQ(loadVisual(dir, "visual:\n  tracker: {clahe: 'off'}\n").tracker.clahe, visual::ClaheMode::kOff);
}

TEST(VisualConfigReader, ShippedConfigsGiveTheTrackerAndDepthDefaults) {
  for (const char* name : {"kitti.yaml", "euroc.yaml", "farm_sim.yaml"}) {
    SCOPED_TRACE(name);
    const VisualConfig c = loadVisualConfig(test::config(name));
    const visual::FeatureTrackerConfig t;
    EXPECT_EQ(c.tracker.max_features, t.max_features);
    EXPECT_DOUBLE_EQ(c.tracker.forward_backward_px, t.forward_backward_px);
    EXPECT_EQ(c.tracker.clahe, t.clahe);
    EXPECT_DOUBLE_EQ(c.tracker.dark_mean, t.dark_mean);
    // The floor is off for real frames; the simulated farm's rendered frames score low and need it (bench/RESULTS.md).
    const bool rendered = std::string(name) == "farm_sim.yaml";
    EXPECT_EQ(c.detector.superpoint.post.min_keypoints, rendered ? 150 : 0);
    EXPECT_DOUBLE_EQ(c.depth.min_depth, visual::DepthAssociationConfig{}.min_depth);
    EXPECT_DOUBLE_EQ(c.depth.max_depth_spread, visual::DepthAssociationConfig{}.max_depth_spread);
  }
}

TEST(VisualConfigReader, TrackerAndDepthMistakesNameFileLineAndKey) {
  test::TempDir dir;
  std::string e = visualErrorOf(dir, "visual:\n  tracker:\n    max_features: 100\n    max_feature: 40\n");
  EXPECT_TRUE(hasPart(e, "visual.yaml")) << e;
  EXPECT_TRUE(hasPart(e, "line 4")) << e;
  EXPECT_TRUE(hasPart(e, "visual.tracker.max_feature")) << e;
  e = visualErrorOf(dir, "visual:\n  depth:\n    window: 5\n");
  EXPECT_TRUE(hasPart(e, "line 3")) << e;
  EXPECT_TRUE(hasPart(e, "visual.depth.window")) << e;
  e = visualErrorOf(dir, "visual:\n  tracker:\n    forward_backward_px: wide\n");
  EXPECT_TRUE(hasPart(e, "line 3")) << e;
  EXPECT_TRUE(hasPart(e, "visual.tracker.forward_backward_px")) << e;
  e = visualErrorOf(dir, "visual:\n  tracker:\n    clahe: sometimes\n");
  EXPECT_TRUE(hasPart(e, "line 3")) << e;
  EXPECT_TRUE(hasPart(e, "off, always or when_dark")) << e;
  e = visualErrorOf(dir, "visual:\n  tracker:\n    flow_window: 20\n");  // parses, fails validate()
  EXPECT_TRUE(hasPart(e, "line 3")) << e;
  EXPECT_TRUE(hasPart(e, "visual.tracker")) << e;
  EXPECT_TRUE(hasPart(e, "flow_window must be odd")) << e;
  e = visualErrorOf(dir, "visual:\n  tracker:\n    min_eigenvalue: -0.001\n");
  EXPECT_TRUE(hasPart(e, "line 3") && hasPart(e, "min_eigenvalue must be finite and >= 0")) << e;
  e = visualErrorOf(dir, "visual:\n  tracker:\n    detect_interval_s: -1\n");
  EXPECT_TRUE(hasPart(e, "line 3") && hasPart(e, "detect_interval_s must be in [0, 60] s")) << e;
  e = visualErrorOf(dir, "visual:\n  tracker:\n    detect_sync_below: -1\n");
  EXPECT_TRUE(hasPart(e, "line 3") && hasPart(e, "detect_sync_below must be >= 0")) << e;
  e = visualErrorOf(dir, "visual:\n  tracker:\n    top_up_below: -5\n");
  EXPECT_TRUE(hasPart(e, "line 3") && hasPart(e, "top_up_below must be >= 0")) << e;
  e = visualErrorOf(dir, "visual:\n  tracker:\n    top_up_below: many\n");
  EXPECT_TRUE(hasPart(e, "line 3") && hasPart(e, "visual.tracker.top_up_below")) << e;
  e = visualErrorOf(dir, "visual:\n  tracker:\n    top_up_min_eigenvalue: -1e-4\n");
  EXPECT_TRUE(hasPart(e, "line 3") && hasPart(e, "top_up_min_eigenvalue must be finite and >= 0")) << e;
  e = visualErrorOf(dir, "visual:\n  depth:\n    min_depth: 5\n    max_depth: 2\n");
  EXPECT_TRUE(hasPart(e, "visual.depth")) << e;
  EXPECT_TRUE(hasPart(e, "line 3")) << e;
}

TEST(VisualConfigReader, RelativeWeightsAreTheWorkingDirectorysElseTheOnesBesideTheConfig) {
  test::TempDir dir;
  test::writeText(dir / "own_superpoint.onnx", "not a network: only its place matters here");
  const std::string beside = (dir / "own_superpoint.onnx").lexically_normal().string();
  EXPECT_EQ(loadVisual(dir, "visual:\n  detector:\n    superpoint:\n      weights: own_superpoint.onnx\n")
                .detector.superpoint.weights,
            beside);
  // Found nowhere: left as written, for the detector's error to name.
  EXPECT_EQ(loadVisual(dir, "visual:\n  detector:\n    superpoint:\n      weights: no_such.onnx\n")
                .detector.superpoint.weights,
            "no_such.onnx");
  // Found in the working directory: that one, as the shipped configs' paths are meant.
  test::TempDir cwd_file;
  const std::string there = (cwd_file / "w.onnx").string();
  test::writeText(cwd_file / "w.onnx", "x");
  const std::string relative = std::filesystem::relative(there).string();
  EXPECT_EQ(loadVisual(dir, "visual:\n  detector:\n    superpoint:\n      weights: " + relative + "\n")
                .detector.superpoint.weights,
            relative);
}

TEST(VisualConfigReader, RelativeWeightsFoundNeitherHereNorBesideTheConfigAreLookedForInTheCallersFolders) {
  test::TempDir dir, repo, other;
  test::writeText(dir / "visual.yaml", "visual:\n  detector:\n    superpoint:\n      weights: models/sp.onnx\n");
  test::writeText(repo / "models" / "sp.onnx", "x");
  const std::string config = (dir / "visual.yaml").string();
  EXPECT_EQ(loadVisualConfig(config, {other.path().string(), repo.path().string()}).detector.superpoint.weights,
            (repo / "models" / "sp.onnx").lexically_normal().string());
  EXPECT_EQ(loadVisualConfig(config, {other.path().string()}).detector.superpoint.weights, "models/sp.onnx");
  // The file beside the config comes first.
  test::writeText(dir / "models" / "sp.onnx", "y");
  EXPECT_EQ(loadVisualConfig(config, {repo.path().string()}).detector.superpoint.weights,
            (dir / "models" / "sp.onnx").lexically_normal().string());
}

TEST(VisualConfigReader, MissingFileIsAnIoError) {
  EXPECT_THROW(loadVisualConfig("/nonexistent/config.yaml"), IoError);
}

}  // namespace
}  // namespace drover::io
