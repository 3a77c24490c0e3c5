// `drover features detect` end to end: a synthetic checkerboard with 35 known corners, the JSON keys scripts rely
// on, drawing, darkening, the real SuperPoint on a KITTI frame, and the errors (one line, exit code 2).
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "io/image_file_io.hpp"
#include "support/cli.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;

// 320 x 240, squares of 40 px: 7 x 5 = 35 inner corners.
fs::path writeCheckerboard(const TempDir& dir, const std::string& name = "board.png") {
  cv::Mat img(240, 320, CV_8UC1);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) img.at<uchar>(y, x) = ((x / 40 + y / 40) % 2) ? 220 : 30;
  cv::GaussianBlur(img, img, cv::Size(5, 5), 1.0);
  const fs::path p = dir / name;
  io::writeImage(p.string(), img);
  return p;
}

TEST(FeaturesDetectCli, ShiTomasiFindsTheCheckerboardCornersAndWritesJson) {
  TempDir dir;
  const fs::path board = writeCheckerboard(dir);
  const CliResult r =
      runDrover("features detect --detector shi-tomasi --json-points " + board.string() + " --json " +
                (dir / "out.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "35 keypoints")) << r.output;
  const auto j = readJson(dir / "out.json");
  EXPECT_EQ(j["detector"], "shi-tomasi");
  EXPECT_EQ(j["settings"]["max_cnt"], 150);
  ASSERT_EQ(j["images"].size(), 1u);
  const auto& im = j["images"][0];
  EXPECT_EQ(im["path"], board.string());
  EXPECT_EQ(im["count"], 35);
  // Cells are 20 x 20 px and corners 40 px apart: each of the 35 corners has a cell of its own.
  EXPECT_DOUBLE_EQ(im["coverage"].get<double>(), 35.0 / 192.0);
  EXPECT_GT(im["ms"].get<double>(), 0.0);
  EXPECT_NEAR(im["mean_intensity"].get<double>(), 125.0, 1.0);  // half 30, half 220
  ASSERT_EQ(im["points"].size(), 35u);
  for (const auto& p : im["points"]) {
    // Every corner sits where four squares meet, between pixels 40 k - 1 and 40 k.
    EXPECT_NEAR(std::fmod(p[0].get<double>() + 0.5 + 20, 40.0), 20.0, 1.5) << p;
    EXPECT_NEAR(std::fmod(p[1].get<double>() + 0.5 + 20, 40.0), 20.0, 1.5) << p;
  }
}

TEST(FeaturesDetectCli, OrbHonoursMaxAndDrawsOneImagePerInput) {
  TempDir dir;
  const fs::path a = writeCheckerboard(dir, "a.png"), b = writeCheckerboard(dir, "b.png");
  const CliResult r = runDrover("features detect --detector orb --max 5 " + a.string() + " " + b.string() + " --draw " +
                                (dir / "kp.png").string() + " --json " + (dir / "o.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = readJson(dir / "o.json");
  ASSERT_EQ(j["images"].size(), 2u);
  for (const auto& im : j["images"]) EXPECT_LE(im["count"].get<int>(), 5);
  for (const char* name : {"kp_0.png", "kp_1.png"}) {
    const cv::Mat drawn = io::readGreyImage((dir / name).string());
    EXPECT_EQ(drawn.size(), cv::Size(320, 240)) << name;
  }
  EXPECT_FALSE(fs::exists(dir / "kp.png"));
}

TEST(FeaturesDetectCli, DarkenedCheckerboardLosesCornersAndJsonStatesTheNoiseModel) {
  TempDir dir;
  const fs::path board = writeCheckerboard(dir);
  const CliResult r = runDrover("features detect --detector shi-tomasi --darken 0.25 " + board.string() + " --json " +
                                (dir / "d.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = readJson(dir / "d.json");
  EXPECT_EQ(j["darken"]["scale"], 0.25);
  EXPECT_EQ(j["darken"]["read_sigma"], 2.0);
  // quality_level 0.01 of the strongest response now admits noise blobs in the flat squares.
  EXPECT_NE(j["images"][0]["count"], 35);
}

TEST(FeaturesDetectCli, SuperPointOnAKittiFrameAtReducedInputSize) {
  const fs::path model = sharedDir() / "models" / "superpoint_v1.onnx";
  const fs::path image = sharedData("kitti/sequences/00/image_2/000000.png");
  DROVER_REQUIRE_SHARED(model);
  DROVER_REQUIRE_SHARED(image);
  TempDir dir;
  const CliResult r =
      runDrover("features detect --config " + std::string(DROVER_SOURCE_DIR) + "/config/kitti.yaml --weights " +
                model.string() + " --input-size 616x184 " + image.string() + " --json " + (dir / "sp.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = readJson(dir / "sp.json");
  EXPECT_EQ(j["detector"], "superpoint");
  EXPECT_EQ(j["settings"]["input_width"], 616);
  EXPECT_EQ(j["settings"]["max_keypoints"], 500);  // from config/kitti.yaml
  EXPECT_GT(j["images"][0]["count"].get<int>(), 200);
  EXPECT_GT(j["images"][0]["coverage"].get<double>(), 0.6);
}

TEST(FeaturesDetectCli, MissingWeightsSayWhereWeightsComeFromAndHowToChooseAnotherDetector) {
  TempDir dir;
  const fs::path board = writeCheckerboard(dir);
  const CliResult r =
      runDrover("features detect --detector superpoint --weights /nonexistent/sp.onnx " + board.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "[error]")) << r.output;
  EXPECT_TRUE(contains(r.output, "/nonexistent/sp.onnx")) << r.output;
  EXPECT_TRUE(contains(r.output, "non-commercial")) << r.output;
  EXPECT_TRUE(contains(r.output, "--detector shi-tomasi|orb")) << r.output;
}

TEST(FeaturesDetectCli, BadArgumentsAreErrors) {
  TempDir dir;
  const fs::path board = writeCheckerboard(dir);
  CliResult r = runDrover("features detect --detector orb /nonexistent/img.png");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "/nonexistent/img.png")) << r.output;
  r = runDrover("features detect --detector sift " + board.string());
  EXPECT_NE(r.exit_code, 0);
  r = runDrover("features detect --input-size 640by480 " + board.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "--input-size")) << r.output;
  writeText(dir / "bad.yaml", "visual:\n  detector:\n    orb:\n      n_feature: 10\n");
  r = runDrover("features detect --config " + (dir / "bad.yaml").string() + " " + board.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "line 4")) << r.output;
  EXPECT_TRUE(contains(r.output, "visual.detector.orb.n_feature")) << r.output;
  writeText(dir / "text.png", "not a PNG\n");
  r = runDrover("features detect --detector orb " + (dir / "text.png").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "text.png")) << r.output;
}

}  // namespace
}  // namespace drover::test
