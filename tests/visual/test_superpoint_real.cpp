// The pretrained SuperPoint (../shared/models/superpoint_v1.onnx, MagicLeap, non-commercial) on real KITTI and
// EuRoC frames: sane counts, keypoints spread over the image, descriptors of unit length, and the reduced input
// size giving a similar spread. Bounds come from the runs recorded in bench/RESULTS.md, with margin.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "io/image_file_io.hpp"
#include "support/shared_data.hpp"
#include "visual/keypoint_coverage.hpp"
#include "visual/superpoint_detector.hpp"

namespace drover::visual {
namespace {

std::filesystem::path modelPath() { return test::sharedDir() / "models" / "superpoint_v1.onnx"; }

std::filesystem::path firstEurocFrame() {
  const auto dir = test::sharedData("euroc/V1_01_easy_micro/mav0/cam0/data");
  std::filesystem::path first;
  if (!std::filesystem::is_directory(dir)) return dir;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".png" && (first.empty() || e.path() < first)) first = e.path();
  return first;
}

SuperPointConfig realConfig(int width = 0, int height = 0) {
  SuperPointConfig c;
  c.weights = modelPath().string();
  c.input_width = width;
  c.input_height = height;
  return c;
}

void expectSane(const Keypoints& k, cv::Size image, std::size_t min_count, double min_coverage) {
  EXPECT_GE(k.points.size(), min_count);
  EXPECT_LE(k.points.size(), 1000u);
  EXPECT_GE(gridCoverage(k.points, image), min_coverage);
  ASSERT_EQ(k.descriptors.rows, static_cast<int>(k.points.size()));
  for (int i = 0; i < k.descriptors.rows; i += 17) EXPECT_NEAR(cv::norm(k.descriptors.row(i)), 1.0, 1e-4);
  for (const cv::Point2f& p : k.points) {
    EXPECT_TRUE(p.x >= 0 && p.y >= 0 && p.x <= image.width - 1 && p.y <= image.height - 1) << p;
  }
  for (std::size_t i = 1; i < k.scores.size(); ++i) EXPECT_GE(k.scores[i - 1], k.scores[i]);
  if (!k.scores.empty()) {
    EXPECT_GE(k.scores.back(), 0.015f);
  }
}

TEST(SuperPointReal, KittiFrameGivesManyWellSpreadKeypoints) {
  const auto image_path = test::sharedData("kitti/sequences/00/image_2/000000.png");
  DROVER_REQUIRE_SHARED(modelPath());
  DROVER_REQUIRE_SHARED(image_path);
  const cv::Mat img = io::readGreyImage(image_path.string());
  SuperPointDetector det(realConfig());
  const Keypoints k = det.detect(img, cv::Mat(), 1000);
  std::cout << "KITTI 00/000000 (1241x376): " << k.points.size() << " keypoints, coverage "
            << gridCoverage(k.points, img.size()) << "\n";
  expectSane(k, img.size(), 500, 0.75);
}

TEST(SuperPointReal, EurocFrameGivesWellSpreadKeypoints) {
  const auto image_path = firstEurocFrame();
  DROVER_REQUIRE_SHARED(modelPath());
  DROVER_REQUIRE_SHARED(image_path);
  const cv::Mat img = io::readGreyImage(image_path.string());
  SuperPointDetector det(realConfig());
  const Keypoints k = det.detect(img, cv::Mat(), 1000);
  std::cout << "EuRoC " << image_path.filename() << " (752x480): " << k.points.size() << " keypoints, coverage "
            << gridCoverage(k.points, img.size()) << "\n";
  expectSane(k, img.size(), 350, 0.45);
}

TEST(SuperPointReal, HalfResolutionInputKeepsTheSpreadAndMapsBackToTheImage) {
  const auto image_path = test::sharedData("kitti/sequences/00/image_2/000000.png");
  DROVER_REQUIRE_SHARED(modelPath());
  DROVER_REQUIRE_SHARED(image_path);
  const cv::Mat img = io::readGreyImage(image_path.string());
  SuperPointDetector det(realConfig(616, 184));
  const Keypoints k = det.detect(img, cv::Mat(), 1000);
  std::cout << "KITTI 00/000000 at 616x184: " << k.points.size() << " keypoints, coverage "
            << gridCoverage(k.points, img.size()) << "\n";
  expectSane(k, img.size(), 200, 0.6);
}

TEST(SuperPointReal, MaskExcludesTheNeighbourhoodsOfLiveTracks) {
  const auto image_path = test::sharedData("kitti/sequences/00/image_2/000000.png");
  DROVER_REQUIRE_SHARED(modelPath());
  DROVER_REQUIRE_SHARED(image_path);
  const cv::Mat img = io::readGreyImage(image_path.string());
  SuperPointDetector det(realConfig(616, 184));
  cv::Mat mask(img.size(), CV_8UC1, cv::Scalar(255));
  for (int x = 100; x < img.cols; x += 200) cv::circle(mask, cv::Point(x, 188), 60, cv::Scalar(0), -1);
  const Keypoints k = det.detect(img, mask, 1000);
  ASSERT_FALSE(k.points.empty());
  for (const cv::Point2f& p : k.points) EXPECT_NE(mask.at<uchar>(cvRound(p.y), cvRound(p.x)), 0) << p;
}

}  // namespace
}  // namespace drover::visual
