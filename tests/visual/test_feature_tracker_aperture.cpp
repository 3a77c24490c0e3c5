// LK on weak gradients: a track on a plain surface's straight edge slides along it (the aperture problem), and the
// tracker's min_eigenvalue (cv::calcOpticalFlowPyrLK's minEigThreshold) is what loses it; a texture's corners stay.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "visual/feature_tracker.hpp"
#include "visual/gftt_detector.hpp"
#include "visual/synthetic_frames.hpp"
#include "visual/tracker_test_util.hpp"

namespace drover::visual {
namespace {

using testing::baseConfig;
using testing::GfttDetector;
using testing::kFrameNs;
using testing::kSize;
using testing::percentile;
using testing::pinhole;

// Points handed over by a detector that finds what it is told to (SuperPoint at a low confidence keeps points on a
// plain wall's edges).
class FixedPoints : public KeypointDetector {
 public:
  explicit FixedPoints(std::vector<cv::Point2f> points) : points_(std::move(points)) {}
  Keypoints detect(const cv::Mat&, const cv::Mat&, int max_count) override {
    Keypoints k;
    for (const cv::Point2f& p : points_)
      if (static_cast<int>(k.points.size()) < max_count) k.points.push_back(p);
    k.scores.assign(k.points.size(), 1.0f);
    return k;
  }
  std::string name() const override { return "fixed"; }

 private:
  std::vector<cv::Point2f> points_;
};

// A plain wall with one straight edge (grey levels 90 | 150, image noise 1 grey level) moving 1.5 px right and 1 px
// down a frame. Along the edge LK has nothing to hold (the aperture problem): a track slides. Returns, for each of
// 10 edge points detected at the first frame and still tracked at the fifth, how far it is from where the edge's
// motion took it [px].
std::vector<double> edgeTrackErrors(double min_eigenvalue) {
  const auto frame = [](int i) {
    cv::Mat image(kSize, CV_8UC1);
    cv::RNG rng(100 + i);
    const double edge = 300 + 1.5 * i;  // [px] the edge's column
    for (int y = 0; y < kSize.height; ++y)
      for (int x = 0; x < kSize.width; ++x) {
        const double v = x < edge - 0.5 ? 90 : (x > edge + 0.5 ? 150 : 90 + 60 * (x - edge + 0.5));
        image.at<unsigned char>(y, x) = cv::saturate_cast<unsigned char>(v + rng.gaussian(1.0));
      }
    return image;
  };
  std::vector<cv::Point2f> on_edge;
  for (int k = 0; k < 10; ++k) on_edge.emplace_back(300.0f, 40.0f + 40.0f * static_cast<float>(k));
  FeatureTrackerConfig c = baseConfig();
  c.min_eigenvalue = min_eigenvalue;
  c.detect_below = 1;  // detect once, at the first frame
  c.ransac = false;    // all points move alike; only the flow is under test
  FeatureTracker tracker(pinhole(), std::make_shared<FixedPoints>(on_edge), c);
  std::map<std::uint64_t, cv::Point2f> first;
  TrackingResult r;
  for (int i = 0; i < 5; ++i) {
    r = tracker.track(i * kFrameNs, frame(i));
    if (i == 0)
      for (const TrackedFeature& f : r.features) first[f.id] = f.pixel;
  }
  std::vector<double> errors;
  for (const TrackedFeature& f : r.features)
    if (first.count(f.id)) errors.push_back(cv::norm(f.pixel - (first[f.id] + cv::Point2f(6.0f, 4.0f))));
  return errors;
}

TEST(FeatureTracker, ATrackSlidingAlongAStraightEdgeIsLostWhereItsGradientsFallBelowTheMinimumEigenvalue) {
  const std::vector<double> loose = edgeTrackErrors(1e-4), platform = edgeTrackErrors(2e-3);
  std::printf("edge tracks left after 5 frames: %zu of 10 with OpenCV's 1e-4 (median %.1f px off), %zu with 2e-3\n",
              loose.size(), percentile(loose, 0.5), platform.size());
  ASSERT_GE(loose.size(), 1u) << "OpenCV's threshold keeps some tracks on the edge";
  EXPECT_GT(percentile(loose, 0.0), 1.0) << "every one of them has slid along the edge";
  EXPECT_TRUE(platform.empty());
}

TEST(FeatureTracker, TheMinimumEigenvalueKeepsTheCornersOfATexture) {
  const auto canvas = testing::texture(1000, 800, 1);
  FeatureTrackerConfig c = baseConfig();
  c.min_eigenvalue = 2e-3;
  FeatureTracker tracker(pinhole(), std::make_shared<GfttDetector>(), c);
  TrackingResult r;
  for (int i = 0; i < 10; ++i) r = tracker.track(i * kFrameNs, testing::view(canvas, {2.37 * i, -1.61 * i}, kSize));
  EXPECT_EQ(r.lost_flow, 0);
  EXPECT_GT(r.tracked, 100);
}

}  // namespace
}  // namespace drover::visual
