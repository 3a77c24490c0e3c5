// SuperPointDetector against an independent numpy reference (tests/visual/make_superpoint_onnx.py: a
// SuperPoint-architecture ONNX with seeded random weights, its forward pass and post-processing in numpy), and
// its errors on bad weights and bad images.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "superpoint_fixture.hpp"
#include "visual/superpoint_detector.hpp"

namespace drover::visual {
namespace {

using test::TempDir;

SuperPointConfig configFor(const std::filesystem::path& onnx) {
  SuperPointConfig c;
  c.weights = onnx.string();
  return c;
}

TEST(SuperPointDetector, MatchesTheNumpyReferenceOnARandomSuperPointNetwork) {
  TempDir dir;
  DROVER_MAKE_SUPERPOINT_ONNX(dir.path(), "ok");
  const test::SuperPointReference ref = test::readSuperPointReference(dir.path());
  ASSERT_GT(ref.count, 50) << "the reference should exercise NMS on many candidates";
  SuperPointDetector det(configFor(dir / "model.onnx"));
  const Keypoints k = det.detect(ref.image, cv::Mat(), 100000);
  ASSERT_EQ(static_cast<int>(k.points.size()), ref.count);
  ASSERT_EQ(k.descriptors.rows, ref.count);
  ASSERT_EQ(k.descriptors.cols, 256);
  ASSERT_EQ(k.descriptors.type(), CV_32F);
  for (int i = 0; i < ref.count; ++i) {
    EXPECT_NEAR(k.points[i].x, ref.points[2 * i], 1e-3) << "keypoint " << i;
    EXPECT_NEAR(k.points[i].y, ref.points[2 * i + 1], 1e-3) << "keypoint " << i;
    EXPECT_NEAR(k.scores[i], ref.scores[i], 1e-4 * ref.scores[i]) << "keypoint " << i;
    for (int c = 0; c < 256; ++c)
      ASSERT_NEAR(k.descriptors.at<float>(i, c), ref.desc[256 * i + c], 1e-4) << "keypoint " << i << " dim " << c;
  }
}

// Its passes cost ~0.1-0.4 s here: the tracker's detection pacing applies to it (KeypointDetector::paced).
TEST(SuperPointDetector, IsPaced) {
  TempDir dir;
  DROVER_MAKE_SUPERPOINT_ONNX(dir.path(), "ok");
  EXPECT_TRUE(SuperPointDetector(configFor(dir / "model.onnx")).paced());
}

TEST(SuperPointDetector, MaxCountKeepsTheStrongestPrefixAndConfigCapsIt) {
  TempDir dir;
  DROVER_MAKE_SUPERPOINT_ONNX(dir.path(), "ok");
  const test::SuperPointReference ref = test::readSuperPointReference(dir.path());
  SuperPointConfig cfg = configFor(dir / "model.onnx");
  cfg.max_keypoints = 30;
  SuperPointDetector det(cfg);
  const Keypoints capped = det.detect(ref.image, cv::Mat(), 1000);
  ASSERT_EQ(capped.points.size(), 30u);
  const Keypoints asked = det.detect(ref.image, cv::Mat(), 12);
  ASSERT_EQ(asked.points.size(), 12u);
  for (int i = 0; i < 12; ++i) {
    EXPECT_NEAR(asked.points[i].x, ref.points[2 * i], 1e-3);
    EXPECT_NEAR(asked.points[i].y, ref.points[2 * i + 1], 1e-3);
  }
  EXPECT_TRUE(det.detect(ref.image, cv::Mat(), 0).points.empty());
}

TEST(SuperPointDetector, ReducedInputSizeScalesKeypointsBackToImagePixels) {
  TempDir dir;
  DROVER_MAKE_SUPERPOINT_ONNX(dir.path(), "ok");
  const test::SuperPointReference ref = test::readSuperPointReference(dir.path());
  SuperPointConfig cfg = configFor(dir / "model.onnx");
  cfg.input_width = ref.image.cols / 2;
  cfg.input_height = ref.image.rows / 2;
  SuperPointDetector det(cfg);
  const Keypoints k = det.detect(ref.image, cv::Mat(), 1000);
  ASSERT_FALSE(k.points.empty());
  for (const cv::Point2f& p : k.points) {
    // Network pixel n maps to image pixel 2n + 0.5 (centre to centre), inside the border of 4 network px.
    const float nx = (p.x - 0.5f) / 2, ny = (p.y - 0.5f) / 2;
    EXPECT_NEAR(nx, std::round(nx), 1e-4);
    EXPECT_NEAR(ny, std::round(ny), 1e-4);
    EXPECT_GE(p.x, 8.5f);
    EXPECT_LE(p.x, ref.image.cols - 8.5f);
  }
}

TEST(SuperPointDetector, MaskedRegionsGetNoKeypoints) {
  TempDir dir;
  DROVER_MAKE_SUPERPOINT_ONNX(dir.path(), "ok");
  const test::SuperPointReference ref = test::readSuperPointReference(dir.path());
  SuperPointDetector det(configFor(dir / "model.onnx"));
  cv::Mat mask(ref.image.size(), CV_8UC1, cv::Scalar(255));
  mask.colRange(0, ref.image.cols / 2).setTo(0);
  const Keypoints k = det.detect(ref.image, mask, 1000);
  ASSERT_FALSE(k.points.empty());
  for (const cv::Point2f& p : k.points) EXPECT_GE(p.x, ref.image.cols / 2);
}

void expectWeightsError(const SuperPointConfig& cfg, const std::string& part) {
  try {
    SuperPointDetector det(cfg);
    FAIL() << "expected std::invalid_argument for " << cfg.weights;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(part), std::string::npos) << what;
    EXPECT_NE(what.find(cfg.weights), std::string::npos) << what;
    EXPECT_NE(what.find("superpoint_v1.onnx"), std::string::npos) << what;
    EXPECT_NE(what.find("non-commercial"), std::string::npos) << what;
    EXPECT_NE(what.find("tools/superpoint_to_onnx.py"), std::string::npos) << what;
    EXPECT_NE(what.find("--detector shi-tomasi|orb"), std::string::npos) << what;
  }
}

TEST(SuperPointDetector, MissingWeightsFileIsAClearError) {
  SuperPointConfig cfg;
  cfg.weights = "/nonexistent/superpoint.onnx";
  expectWeightsError(cfg, "file not found");
}

TEST(SuperPointDetector, MalformedWeightsFileIsAClearError) {
  TempDir dir;
  std::ofstream(dir / "garbage.onnx") << "this is not a protobuf \x01\x02\x03 at all";
  expectWeightsError(configFor(dir / "garbage.onnx"), "not a readable ONNX network");
  std::ofstream(dir / "empty.onnx").close();
  expectWeightsError(configFor(dir / "empty.onnx"), "not a readable ONNX network");
}

TEST(SuperPointDetector, NetworkWithWrongOutputShapeIsAClearError) {
  TempDir dir;
  DROVER_MAKE_SUPERPOINT_ONNX(dir.path(), "semi64");
  expectWeightsError(configFor(dir / "model.onnx"), "'semi'");
}

TEST(SuperPointDetector, NetworkWithoutDescriptorOutputIsAClearError) {
  TempDir dir;
  DROVER_MAKE_SUPERPOINT_ONNX(dir.path(), "no-desc");
  expectWeightsError(configFor(dir / "model.onnx"), "'desc'");
}

TEST(SuperPointDetector, InvalidConfigIsRejectedBeforeLoading) {
  SuperPointConfig cfg;
  cfg.input_width = 100;  // not a multiple of 8
  cfg.input_height = 80;
  EXPECT_NE(cfg.validate().find("multiples of 8"), std::string::npos);
  EXPECT_THROW(SuperPointDetector{cfg}, std::invalid_argument);
  cfg = SuperPointConfig{};
  cfg.post.confidence_threshold = 0;
  EXPECT_FALSE(cfg.validate().empty());
}

void expectImageError(KeypointDetector& det, const cv::Mat& image, const cv::Mat& mask, int max_count,
                      const std::string& part) {
  try {
    det.detect(image, mask, max_count);
    FAIL() << "expected std::invalid_argument (" << part << ")";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(SuperPointDetector, BadImagesAndMasksAreClearErrors) {
  TempDir dir;
  DROVER_MAKE_SUPERPOINT_ONNX(dir.path(), "ok");
  SuperPointDetector det(configFor(dir / "model.onnx"));
  const cv::Mat grey(96, 128, CV_8UC1, cv::Scalar(100));
  expectImageError(det, cv::Mat(), cv::Mat(), 10, "empty image");
  expectImageError(det, cv::Mat(96, 128, CV_8UC3, cv::Scalar::all(100)), cv::Mat(), 10, "CV_8UC3");
  expectImageError(det, cv::Mat(96, 128, CV_16UC1, cv::Scalar(100)), cv::Mat(), 10, "CV_16UC1");
  expectImageError(det, grey, cv::Mat(95, 128, CV_8UC1, cv::Scalar(255)), 10, "mask size 128x95");
  expectImageError(det, grey, cv::Mat(96, 128, CV_32FC1, cv::Scalar(1)), 10, "CV_32FC1");
  expectImageError(det, grey, cv::Mat(), -1, "max_count");
}

}  // namespace
}  // namespace drover::visual
