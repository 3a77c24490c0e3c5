// The corner top-up of the KLT tracker (FeatureTrackerConfig::top_up_below): where the detector's points fall below
// its LK floor (SuperPoint's on a plain wall), Shi-Tomasi corners, each tracked at its own lower floor, keep the frame
// tracked; where the detector keeps enough tracks, the top-up never acts.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <string>
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

// A detector that returns a regular grid wherever the mask allows, whatever the image: points chosen by a score
// that is not LK's (SuperPoint's at a low confidence on a plain wall).
class GridPoints : public KeypointDetector {
 public:
  Keypoints detect(const cv::Mat&, const cv::Mat& mask, int max_count) override {
    Keypoints k;
    for (int y = 20; y < kSize.height - 20; y += 32)
      for (int x = 20; x < kSize.width - 20; x += 32)
        if (static_cast<int>(k.points.size()) < max_count && (mask.empty() || mask.at<unsigned char>(y, x)))
          k.points.emplace_back(static_cast<float>(x) + 0.3f, static_cast<float>(y) + 0.6f);
    k.scores.assign(k.points.size(), 1.0f);
    return k;
  }
  std::string name() const override { return "grid"; }
};

// The blob texture at 15 % of its contrast (amplitude ~7 grey levels): LK's minimum eigenvalues scale with the
// contrast squared, so its corners fall between OpenCV's floor (1e-4) and the drover preset's for SuperPoint (2e-3).
cv::Mat faint(const testing::BlobCanvas& canvas, cv::Point2d shift) {
  cv::Mat image;
  testing::view(canvas, shift, kSize).convertTo(image, CV_8UC1, 0.15, 128 * 0.85);
  return image;
}

constexpr int kFrames = 15;
const cv::Point2d kStep(1.7, -0.9);  // [px / frame]

struct FaintRun {
  std::vector<int> tracked;            // per frame from the second
  std::vector<double> corner_step_errors;  // [px] frame-to-frame flow errors of the corners' tracks
  int detector_tracks_carried = 0;     // detector points that survived a frame
  int corners_added = 0;
};

FaintRun trackFaintWall(int top_up_below) {
  const auto canvas = testing::texture(1000, 800, 4);
  FeatureTrackerConfig c = baseConfig();
  c.min_eigenvalue = 2e-3;  // the drover preset's floor for the detector's tracks
  c.top_up_below = top_up_below;
  c.top_up_min_eigenvalue = 1e-4;
  c.ransac = false;  // one rigid motion; only the flow and the floors are under test
  FeatureTracker tracker(pinhole(), std::make_shared<GridPoints>(), c);
  FaintRun run;
  std::map<std::uint64_t, cv::Point2f> previous;
  for (int i = 0; i < kFrames; ++i) {
    const TrackingResult r = tracker.track(i * kFrameNs, faint(canvas, kStep * i));
    run.corners_added += r.added_corners;
    if (i > 0) run.tracked.push_back(r.tracked);
    std::map<std::uint64_t, cv::Point2f> now;
    for (const TrackedFeature& f : r.features) {
      now[f.id] = f.pixel;
      if (f.track_length < 2) continue;
      if (!f.corner) ++run.detector_tracks_carried;
      if (f.corner && previous.count(f.id))
        run.corner_step_errors.push_back(cv::norm(cv::Point2d(f.pixel - previous[f.id]) - kStep));
    }
    previous = now;
  }
  return run;
}

TEST(FeatureTrackerTopUp, OnAFaintWallCornersAtTheirOwnFloorKeepTheFrameTrackedWhereTheDetectorsPointsAreLost) {
  const FaintRun alone = trackFaintWall(0), topped = trackFaintWall(40);
  std::printf("faint wall, tracks carried a frame (median): detector alone %.0f, with the corner top-up %.0f; "
              "corner flow error median %.3f px, p95 %.3f px\n",
              percentile({alone.tracked.begin(), alone.tracked.end()}, 0.5),
              percentile({topped.tracked.begin(), topped.tracked.end()}, 0.5),
              percentile(topped.corner_step_errors, 0.5), percentile(topped.corner_step_errors, 0.95));
  for (int n : alone.tracked) EXPECT_LT(n, 5) << "the detector's points must fall below its floor on this wall";
  EXPECT_EQ(alone.corners_added, 0);
  // The first frame is the detector's alone (nothing carried yet); from the third on the corners are in.
  for (std::size_t k = 1; k < topped.tracked.size(); ++k) EXPECT_GE(topped.tracked[k], 40) << "frame " << k + 1;
  EXPECT_EQ(topped.detector_tracks_carried, 0) << "the detector's own tracks keep its floor";
  ASSERT_GT(topped.corner_step_errors.size(), 300u);
  EXPECT_LT(percentile(topped.corner_step_errors, 0.5), 0.1);
  EXPECT_LT(percentile(topped.corner_step_errors, 0.95), 0.3);
}

// On a textured view the detector keeps ~100 tracks: the top-up must not act, and the tracks must be the same, bit
// for bit, as without it (the preset is unchanged wherever the detector copes).
TEST(FeatureTrackerTopUp, WhereTheDetectorKeepsEnoughTracksTheTopUpNeverActsAndChangesNothing) {
  const auto canvas = testing::texture(1000, 800, 5);
  FeatureTrackerConfig c = baseConfig();
  FeatureTracker plain(pinhole(), std::make_shared<GfttDetector>(), c);
  c.top_up_below = 40;
  FeatureTracker topped(pinhole(), std::make_shared<GfttDetector>(), c);
  for (int i = 0; i < kFrames; ++i) {
    const cv::Mat image = testing::view(canvas, kStep * i, kSize);
    const TrackingResult a = plain.track(i * kFrameNs, image), b = topped.track(i * kFrameNs, image);
    EXPECT_EQ(b.added_corners, 0) << "frame " << i;
    ASSERT_EQ(a.features.size(), b.features.size()) << "frame " << i;
    for (std::size_t k = 0; k < a.features.size(); ++k) {
      EXPECT_EQ(a.features[k].id, b.features[k].id);
      EXPECT_EQ(a.features[k].pixel, b.features[k].pixel);
      EXPECT_FALSE(b.features[k].corner);
    }
  }
}

TEST(FeatureTrackerTopUp, ABadTopUpSettingIsRejectedByName) {
  FeatureTrackerConfig below = baseConfig();
  below.top_up_below = -1;
  EXPECT_NE(below.validate().find("top_up_below"), std::string::npos);
  FeatureTrackerConfig floor = baseConfig();
  floor.top_up_min_eigenvalue = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(floor.validate().find("top_up_min_eigenvalue"), std::string::npos);
  EXPECT_THROW(FeatureTracker(pinhole(), std::make_shared<GridPoints>(), floor), std::invalid_argument);
}

}  // namespace
}  // namespace drover::visual
