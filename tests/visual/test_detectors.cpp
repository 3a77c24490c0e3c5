// Shi-Tomasi and ORB detectors on a synthetic checkerboard with known corners, the coverage measure, and the
// detector factory.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "visual/detector_factory.hpp"
#include "visual/image_darkening.hpp"
#include "visual/keypoint_coverage.hpp"

namespace drover::visual {
namespace {

constexpr int kSquare = 40;  // [px]

// A 320 x 240 checkerboard whose inner corners are at multiples of 40 px (blurred so corners are not aliased).
cv::Mat checkerboard() {
  cv::Mat img(240, 320, CV_8UC1);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) img.at<uchar>(y, x) = ((x / kSquare + y / kSquare) % 2) ? 220 : 30;
  cv::GaussianBlur(img, img, cv::Size(5, 5), 1.0);
  return img;
}

double distanceToGridCorner(cv::Point2f p) {
  // Corners lie between pixels 39 and 40: at 39.5 in OpenCV's pixel-centre convention.
  const float gx = std::round((p.x + 0.5f) / kSquare) * kSquare - 0.5f;
  const float gy = std::round((p.y + 0.5f) / kSquare) * kSquare - 0.5f;
  return std::hypot(p.x - gx, p.y - gy);
}

TEST(ShiTomasiDetector, FindsTheCheckerboardCornersStrongestFirst) {
  ShiTomasiConfig cfg;
  cfg.min_dist = 20;
  ShiTomasiDetector det(cfg);
  const Keypoints k = det.detect(checkerboard(), cv::Mat(), 1000);
  ASSERT_EQ(k.points.size(), 35u);  // 7 x 5 inner corners
  for (const cv::Point2f& p : k.points) EXPECT_LT(distanceToGridCorner(p), 1.5) << p;
  for (std::size_t i = 1; i < k.scores.size(); ++i) EXPECT_GE(k.scores[i - 1], k.scores[i]);
  EXPECT_TRUE(k.descriptors.empty());
}

TEST(ShiTomasiDetector, HonoursMaskMaxCountAndMinDistance) {
  ShiTomasiConfig cfg;
  cfg.min_dist = 50;  // more than a square: neighbouring corners exclude each other
  ShiTomasiDetector det(cfg);
  cv::Mat mask(240, 320, CV_8UC1, cv::Scalar(0));
  mask.colRange(160, 320).setTo(255);
  const Keypoints k = det.detect(checkerboard(), mask, 1000);
  ASSERT_FALSE(k.points.empty());
  for (std::size_t i = 0; i < k.points.size(); ++i) {
    EXPECT_GE(k.points[i].x, 160);
    for (std::size_t j = 0; j < i; ++j) EXPECT_GE(cv::norm(k.points[i] - k.points[j]), 50);
  }
  EXPECT_EQ(det.detect(checkerboard(), cv::Mat(), 3).points.size(), 3u);
  EXPECT_TRUE(det.detect(checkerboard(), cv::Mat(), 0).points.empty());
}

TEST(ShiTomasiDetector, ConfigCapsTheCount) {
  ShiTomasiConfig cfg;
  cfg.max_cnt = 5;
  cfg.min_dist = 10;
  EXPECT_EQ(ShiTomasiDetector(cfg).detect(checkerboard(), cv::Mat(), 1000).points.size(), 5u);
}

TEST(OrbDetector, FindsCornersWithDescriptorsHonouringMaskAndCount) {
  OrbDetector det;
  const cv::Mat img = checkerboard();
  const Keypoints all = det.detect(img, cv::Mat(), 1000);
  ASSERT_GT(all.points.size(), 20u);
  EXPECT_EQ(all.descriptors.rows, static_cast<int>(all.points.size()));
  EXPECT_EQ(all.descriptors.cols, 32);
  EXPECT_EQ(all.descriptors.type(), CV_8U);
  for (std::size_t i = 1; i < all.scores.size(); ++i) EXPECT_GE(all.scores[i - 1], all.scores[i]);
  cv::Mat mask(240, 320, CV_8UC1, cv::Scalar(0));
  mask.rowRange(0, 120).setTo(255);
  const Keypoints top = det.detect(img, mask, 1000);
  ASSERT_FALSE(top.points.empty());
  for (const cv::Point2f& p : top.points) EXPECT_LT(cvRound(p.y), 120);
  const Keypoints few = det.detect(img, cv::Mat(), 7);
  EXPECT_LE(few.points.size(), 7u);
  EXPECT_GE(few.points.size(), 1u);
  EXPECT_TRUE(det.detect(img, cv::Mat(), 0).points.empty());
}

TEST(Detectors, RejectBadImagesAndMasksNamingTheProblem) {
  ShiTomasiDetector st;
  OrbDetector orb;
  const cv::Mat grey(240, 320, CV_8UC1, cv::Scalar(0));
  for (KeypointDetector* d : std::vector<KeypointDetector*>{&st, &orb}) {
    EXPECT_THROW(d->detect(cv::Mat(), cv::Mat(), 10), std::invalid_argument) << d->name();
    EXPECT_THROW(d->detect(cv::Mat(240, 320, CV_8UC3), cv::Mat(), 10), std::invalid_argument) << d->name();
    EXPECT_THROW(d->detect(cv::Mat(240, 320, CV_16UC1), cv::Mat(), 10), std::invalid_argument) << d->name();
    EXPECT_THROW(d->detect(grey, cv::Mat(240, 321, CV_8UC1), 10), std::invalid_argument) << d->name();
    EXPECT_THROW(d->detect(grey, cv::Mat(240, 320, CV_16UC1), 10), std::invalid_argument) << d->name();
    EXPECT_THROW(d->detect(grey, cv::Mat(), -1), std::invalid_argument) << d->name();
  }
}

TEST(Detectors, InvalidConfigsAreRejected) {
  ShiTomasiConfig st;
  st.quality_level = 0;
  EXPECT_THROW(ShiTomasiDetector{st}, std::invalid_argument);
  OrbConfig orb;
  orb.scale_factor = 1.0;
  EXPECT_THROW(OrbDetector{orb}, std::invalid_argument);
}

TEST(DetectorFactory, MakesTheChosenDetectorAndParsesNames) {
  DetectorConfig cfg;
  cfg.type = DetectorType::kShiTomasi;
  EXPECT_EQ(makeDetector(cfg)->name(), "shi-tomasi");
  cfg.type = DetectorType::kOrb;
  EXPECT_EQ(makeDetector(cfg)->name(), "orb");
  for (const char* n : {"superpoint", "shi-tomasi", "orb"}) EXPECT_EQ(detectorTypeName(parseDetectorType(n)), n);
  EXPECT_THROW(parseDetectorType("sift"), std::invalid_argument);
  cfg.type = DetectorType::kSuperPoint;
  cfg.superpoint.weights = "/nonexistent.onnx";
  EXPECT_THROW(makeDetector(cfg), std::invalid_argument);
}

// The tracker's detection pacing holds only a detector that says it is slow: a preset or --detector that swaps
// SuperPoint for Shi-Tomasi must not inherit it (paced Shi-Tomasi starved the lvi-sam preset's VIS). SuperPoint's
// side is in test_superpoint.cpp (it needs a network).
TEST(DetectorFactory, ShiTomasiAndOrbAreNotPaced) {
  for (const DetectorType fast : {DetectorType::kShiTomasi, DetectorType::kOrb}) {
    DetectorConfig cfg;
    cfg.type = fast;
    EXPECT_FALSE(makeDetector(cfg)->paced()) << detectorTypeName(fast);
  }
}

TEST(GridCoverage, CountsOccupiedCells) {
  const cv::Size img(160, 120);  // 16 x 12 cells of 10 x 10 px
  EXPECT_EQ(gridCoverage({}, img), 0.0);
  EXPECT_DOUBLE_EQ(gridCoverage({{0, 0}, {1, 1}, {159, 119}}, img), 2.0 / 192);
  std::vector<cv::Point2f> every;
  for (int y = 5; y < 120; y += 10)
    for (int x = 5; x < 160; x += 10) every.emplace_back(x, y);
  EXPECT_DOUBLE_EQ(gridCoverage(every, img), 1.0);
  EXPECT_DOUBLE_EQ(gridCoverage({{-5, 3}, {200, 3}}, img), 0.0);
  EXPECT_THROW(gridCoverage({}, cv::Size(0, 10)), std::invalid_argument);
}

}  // namespace
}  // namespace drover::visual

namespace drover::visual {
namespace {

TEST(DarkenImage, ScalesTheMeanAndAddsTheStatedNoise) {
  const cv::Mat flat(200, 200, CV_8UC1, cv::Scalar(160));
  DarkeningConfig cfg;  // 0.25, shot gain 1, read sigma 2
  const cv::Mat dark = darkenImage(flat, cfg);
  cv::Scalar mean, sd;
  cv::meanStdDev(dark, mean, sd);
  EXPECT_NEAR(mean[0], 40.0, 0.2);
  EXPECT_NEAR(sd[0], std::sqrt(40.0 + 4.0), 0.3);  // shot variance 40 + read variance 4 (+ rounding 1/12)
  EXPECT_EQ(cv::norm(dark, darkenImage(flat, cfg), cv::NORM_INF), 0.0);  // seeded
  cfg.seed = 2;
  EXPECT_GT(cv::norm(dark, darkenImage(flat, cfg), cv::NORM_INF), 0.0);
  cfg.scale = 0;
  EXPECT_THROW(darkenImage(flat, cfg), std::invalid_argument);
  EXPECT_THROW(darkenImage(cv::Mat(10, 10, CV_8UC3), DarkeningConfig{}), std::invalid_argument);
}

}  // namespace
}  // namespace drover::visual
