// SuperPoint post-processing alone on hand-made network outputs, where the answer is known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "visual/superpoint_postprocess.hpp"

namespace drover::visual {
namespace {

constexpr int kHc = 6, kWc = 8;  // a 64 x 48 network image

// Logits where every cell is certainly empty: dustbin 0, keypoint channels -30 (probability ~1e-13).
cv::Mat emptySemi() {
  const int shape[4] = {1, 65, kHc, kWc};
  cv::Mat semi(4, shape, CV_32F, cv::Scalar(-30));
  for (int y = 0; y < kHc; ++y)
    for (int x = 0; x < kWc; ++x) semi.at<float>(cv::Vec4i(0, 64, y, x)) = 0;
  return semi;
}

// Gives pixel (x, y) the probability p (the cell's dustbin takes the rest, other pixels stay ~0).
void setProbability(cv::Mat& semi, int x, int y, double p) {
  const int cx = x / 8, cy = y / 8, c = (y % 8) * 8 + x % 8;
  semi.at<float>(cv::Vec4i(0, c, cy, cx)) = 0;
  semi.at<float>(cv::Vec4i(0, 64, cy, cx)) = static_cast<float>(std::log((1 - p) / p));
}

Keypoints run(const cv::Mat& semi, const cv::Mat& mask = cv::Mat(), SuperPointPostConfig cfg = {}) {
  SuperPointPostprocessor post(cfg);
  return post.run(semi, cv::Mat(), mask, 1000);
}

TEST(SuperPointPostprocess, ASinglePeakIsOneKeypointAtItsPixelWithItsProbability) {
  cv::Mat semi = emptySemi();
  setProbability(semi, 21, 13, 0.8);  // cell (2, 1), channel 5*8 + 5
  const Keypoints k = run(semi);
  ASSERT_EQ(k.points.size(), 1u);
  EXPECT_EQ(k.points[0], cv::Point2f(21, 13));
  EXPECT_NEAR(k.scores[0], 0.8, 1e-6);
  EXPECT_TRUE(k.descriptors.empty());
}

TEST(SuperPointPostprocess, OfTwoPeaksWithinTheNmsRadiusOnlyTheStrongerSurvives) {
  cv::Mat semi = emptySemi();
  setProbability(semi, 20, 20, 0.5);
  setProbability(semi, 24, 23, 0.7);  // Chebyshev distance 4 = radius: suppressed neighbour
  Keypoints k = run(semi);
  ASSERT_EQ(k.points.size(), 1u);
  EXPECT_EQ(k.points[0], cv::Point2f(24, 23));
  setProbability(semi, 20, 20, 0.9);  // now the other one is stronger
  k = run(semi);
  ASSERT_EQ(k.points.size(), 1u);
  EXPECT_EQ(k.points[0], cv::Point2f(20, 20));
}

TEST(SuperPointPostprocess, PeaksFartherThanTheNmsRadiusBothSurviveStrongestFirst) {
  cv::Mat semi = emptySemi();
  setProbability(semi, 20, 20, 0.5);
  setProbability(semi, 25, 20, 0.7);  // distance 5 > 4
  const Keypoints k = run(semi);
  ASSERT_EQ(k.points.size(), 2u);
  EXPECT_EQ(k.points[0], cv::Point2f(25, 20));
  EXPECT_EQ(k.points[1], cv::Point2f(20, 20));
  EXPECT_GT(k.scores[0], k.scores[1]);
}

TEST(SuperPointPostprocess, PointsWithinTheBorderAreRemovedButStillSuppressNeighbours) {
  cv::Mat semi = emptySemi();
  setProbability(semi, 3, 20, 0.9);   // x < 4: border
  setProbability(semi, 6, 20, 0.5);   // within the border point's NMS window
  setProbability(semi, 4, 40, 0.6);   // x = 4: first column kept
  setProbability(semi, 60, 43, 0.5);  // x = W-4, y = H-5: x out, y in
  setProbability(semi, 59, 10, 0.5);  // x = W-5: kept
  const Keypoints k = run(semi);
  ASSERT_EQ(k.points.size(), 2u);
  EXPECT_EQ(k.points[0], cv::Point2f(4, 40));
  EXPECT_EQ(k.points[1], cv::Point2f(59, 10));
}

TEST(SuperPointPostprocess, ProbabilitiesBelowTheThresholdAreNotKeypoints) {
  cv::Mat semi = emptySemi();
  setProbability(semi, 20, 20, 0.014);
  setProbability(semi, 40, 20, 0.016);
  Keypoints k = run(semi);
  ASSERT_EQ(k.points.size(), 1u);
  EXPECT_EQ(k.points[0], cv::Point2f(40, 20));
  SuperPointPostConfig strict;
  strict.confidence_threshold = 0.5;
  EXPECT_TRUE(run(semi, cv::Mat(), strict).points.empty());
}

TEST(SuperPointPostprocess, TheMinKeypointsFloorFillsWithTheStrongestBelowThreshold) {
  cv::Mat semi = emptySemi();
  setProbability(semi, 20, 20, 0.5);    // above 0.015
  setProbability(semi, 40, 20, 0.010);  // below: the two strongest weak peaks
  setProbability(semi, 20, 35, 0.008);
  setProbability(semi, 40, 35, 0.004);
  SuperPointPostConfig cfg;
  EXPECT_EQ(run(semi, cv::Mat(), cfg).points.size(), 1u) << "off by default: only the peak above threshold";
  cfg.min_keypoints = 3;
  Keypoints k = run(semi, cv::Mat(), cfg);
  ASSERT_EQ(k.points.size(), 3u) << "filled up to the floor, not beyond";
  EXPECT_EQ(k.points[0], cv::Point2f(20, 20));
  EXPECT_EQ(k.points[1], cv::Point2f(40, 20));
  EXPECT_EQ(k.points[2], cv::Point2f(20, 35));
  EXPECT_NEAR(k.scores[2], 0.008, 1e-6);
  cv::Mat mask(48, 64, CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(36, 16, 8, 8)).setTo(0);  // hides (40, 20): the floor respects the mask
  k = run(semi, mask, cfg);
  ASSERT_EQ(k.points.size(), 3u);
  EXPECT_EQ(k.points[1], cv::Point2f(20, 35));
  EXPECT_EQ(k.points[2], cv::Point2f(40, 35));
  cfg.min_keypoints = 1;  // met by the threshold alone: nothing weak is added
  EXPECT_EQ(run(semi, cv::Mat(), cfg).points.size(), 1u);
  cfg.min_keypoints = 3;
  SuperPointPostprocessor post(cfg);
  EXPECT_EQ(post.run(semi, cv::Mat(), cv::Mat(), 2).points.size(), 2u) << "the floor never exceeds max_count";
  cfg.min_keypoints = -1;
  EXPECT_NE(cfg.validate(), "");
}

TEST(SuperPointPostprocess, MaskedCandidatesAreDroppedBeforeNms) {
  cv::Mat semi = emptySemi();
  setProbability(semi, 20, 20, 0.9);
  setProbability(semi, 23, 20, 0.5);
  cv::Mat mask(48, 64, CV_8UC1, cv::Scalar(255));
  mask.at<uchar>(20, 20) = 0;  // the strong one is under a live track
  const Keypoints k = run(semi, mask);
  ASSERT_EQ(k.points.size(), 1u);
  EXPECT_EQ(k.points[0], cv::Point2f(23, 20));
}

TEST(SuperPointPostprocess, MaxCountKeepsTheStrongest) {
  cv::Mat semi = emptySemi();
  for (int i = 0; i < 5; ++i) setProbability(semi, 10 + 10 * i, 24, 0.2 + 0.1 * i);
  SuperPointPostprocessor post;
  const Keypoints k = post.run(semi, cv::Mat(), cv::Mat(), 2);
  ASSERT_EQ(k.points.size(), 2u);
  EXPECT_EQ(k.points[0], cv::Point2f(50, 24));
  EXPECT_EQ(k.points[1], cv::Point2f(40, 24));
  EXPECT_TRUE(post.run(semi, cv::Mat(), cv::Mat(), 0).points.empty());
}

// A ceiling of strong peaks in the top half, a floor of weak ones in the bottom half (the lighting course's frames):
// by score a top-3 is all ceiling; spread over a 2 x 2 grid it takes each cell's best first.
TEST(SuperPointPostprocess, SpreadOverAGridTakesEveryCellsStrongestBeforeAnyCellsSecond) {
  cv::Mat semi = emptySemi();
  setProbability(semi, 10, 8, 0.9);   // cell (0, 0)
  setProbability(semi, 20, 8, 0.85);  // cell (0, 0)
  setProbability(semi, 45, 8, 0.8);   // cell (1, 0)
  setProbability(semi, 55, 8, 0.75);  // cell (1, 0)
  setProbability(semi, 12, 40, 0.1);  // cell (0, 1), the floor's best
  setProbability(semi, 22, 40, 0.05);
  setProbability(semi, 50, 40, 0.2);  // cell (1, 1)
  SuperPointPostConfig cfg;
  SuperPointPostprocessor by_score(cfg);
  Keypoints k = by_score.run(semi, cv::Mat(), cv::Mat(), 3);
  ASSERT_EQ(k.points.size(), 3u);
  for (const cv::Point2f& p : k.points) EXPECT_LT(p.y, 24) << "by score alone the ceiling takes all three";
  cfg.grid_cols = cfg.grid_rows = 2;
  SuperPointPostprocessor spread(cfg);
  k = spread.run(semi, cv::Mat(), cv::Mat(), 7);
  ASSERT_EQ(k.points.size(), 7u);
  // Rank 0 of each cell, by score; then rank 1 of each, by score.
  const std::vector<cv::Point2f> expected = {{10, 8}, {45, 8}, {50, 40}, {12, 40}, {20, 8}, {55, 8}, {22, 40}};
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(k.points[i], expected[i]) << i;
  EXPECT_NEAR(k.scores[3], 0.1, 1e-6) << "scores stay each point's own";
  k = spread.run(semi, cv::Mat(), cv::Mat(), 4);
  ASSERT_EQ(k.points.size(), 4u);
  EXPECT_EQ(k.points[3], cv::Point2f(12, 40)) << "a top-4 holds the floor's best of both cells";
}

// The floor's fill below the threshold is spread too: a dark floor's best point comes in before a lit ceiling's
// second, where by score the ceiling's weak points would fill the floor's quota.
TEST(SuperPointPostprocess, TheFloorsFillIsSpreadOverTheGridWhenOneIsSet) {
  cv::Mat semi = emptySemi();
  setProbability(semi, 10, 8, 0.5);     // above 0.015, top half
  setProbability(semi, 30, 8, 0.012);   // below, top half
  setProbability(semi, 50, 8, 0.011);   // below, top half
  setProbability(semi, 20, 40, 0.002);  // below, bottom half: the dark floor
  SuperPointPostConfig cfg;
  cfg.min_keypoints = 2;
  Keypoints k = run(semi, cv::Mat(), cfg);
  ASSERT_EQ(k.points.size(), 2u);
  EXPECT_EQ(k.points[1], cv::Point2f(30, 8)) << "by score: the top half's weak point";
  cfg.grid_cols = 1;
  cfg.grid_rows = 2;
  k = run(semi, cv::Mat(), cfg);
  ASSERT_EQ(k.points.size(), 2u);
  EXPECT_EQ(k.points[0], cv::Point2f(10, 8));
  EXPECT_EQ(k.points[1], cv::Point2f(20, 40)) << "spread: the bottom row's best";
}

TEST(SuperPointPostprocess, AGridNeedsBothSidesOrNeither) {
  SuperPointPostConfig cfg;
  EXPECT_EQ(cfg.validate(), "") << "off by default";
  cfg.grid_cols = 8;
  EXPECT_NE(cfg.validate().find("grid_rows"), std::string::npos);
  cfg.grid_rows = 6;
  EXPECT_EQ(cfg.validate(), "");
  cfg.grid_rows = -1;
  EXPECT_NE(cfg.validate(), "");
  EXPECT_THROW(SuperPointPostprocessor{cfg}, std::invalid_argument);
}

TEST(SuperPointPostprocess, DescriptorsAreBilinearBetweenCellCentresAndUnitLength) {
  cv::Mat semi = emptySemi();
  setProbability(semi, 12, 11, 0.9);  // u = (12 - 3.5) / 8 = 1.0625, v = (11 - 3.5) / 8 = 0.9375
  const int shape[4] = {1, 256, kHc, kWc};
  cv::Mat desc(4, shape, CV_32F, cv::Scalar(0));
  // Cells (u, v): (1, 0) -> 2 e0 (normalised to e0), (2, 0) -> e1, (1, 1) -> 3 e2, (2, 1) -> e3.
  desc.at<float>(cv::Vec4i(0, 0, 0, 1)) = 2;
  desc.at<float>(cv::Vec4i(0, 1, 0, 2)) = 1;
  desc.at<float>(cv::Vec4i(0, 2, 1, 1)) = 3;
  desc.at<float>(cv::Vec4i(0, 3, 1, 2)) = 1;
  SuperPointPostprocessor post;
  const Keypoints k = post.run(semi, desc, cv::Mat(), 10);
  ASSERT_EQ(k.descriptors.rows, 1);
  const double fu = 0.0625, fv = 0.9375;
  const double w[4] = {(1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv};
  const double norm = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2] + w[3] * w[3]);
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(k.descriptors.at<float>(0, c), w[c] / norm, 1e-6) << c;
  EXPECT_NEAR(cv::norm(k.descriptors.row(0)), 1.0, 1e-6);
}

TEST(SuperPointPostprocess, OutputsOfTheWrongShapeAreRejected) {
  SuperPointPostprocessor post;
  const int bad_shape[4] = {1, 64, kHc, kWc};
  EXPECT_THROW(post.run(cv::Mat(4, bad_shape, CV_32F, cv::Scalar(0)), cv::Mat(), cv::Mat(), 10), std::invalid_argument);
  const int desc_shape[4] = {1, 256, kHc, kWc + 1};
  EXPECT_THROW(post.run(emptySemi(), cv::Mat(4, desc_shape, CV_32F, cv::Scalar(0)), cv::Mat(), 10),
               std::invalid_argument);
  EXPECT_THROW(post.run(emptySemi(), cv::Mat(), cv::Mat(47, 64, CV_8UC1), 10), std::invalid_argument);
  EXPECT_THROW(post.run(emptySemi(), cv::Mat(), cv::Mat(), -1), std::invalid_argument);
}

}  // namespace
}  // namespace drover::visual
