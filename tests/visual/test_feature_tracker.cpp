// KLT tracker on synthetic sequences with known motion, and on real EuRoC frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <thread>

#include "io/dataset.hpp"
#include "support/shared_data.hpp"
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

// Where each feature was first seen: frame index and pixel.
struct Origin {
  int frame;
  cv::Point2f pixel;
};

// Frame-to-frame flow errors on a sub-pixel translation: median within 0.05 px, 95 % within 0.1 px (the rest, on
// weakly textured windows, within the 0.5 px forward-backward threshold); ids persist and lengths grow by one a frame;
// velocity = step / f / dt.
TEST(FeatureTracker, TracksATranslatedTextureToATenthOfAPixelAndKeepsIds) {
  const auto canvas = testing::texture(1000, 800, 1);
  FeatureTracker tracker(pinhole(), std::make_shared<GfttDetector>(), baseConfig());
  const cv::Point2d step(2.37, -1.61);  // [px / frame]
  std::map<std::uint64_t, Origin> origin, previous;
  std::vector<double> step_errors, drift, velocity_errors;
  for (int i = 0; i < 20; ++i) {
    const TrackingResult r = tracker.track(i * kFrameNs, testing::view(canvas, step * i, kSize));
    for (const TrackedFeature& f : r.features) {
      if (!origin.count(f.id)) {
        EXPECT_EQ(f.track_length, 1);
        EXPECT_EQ(f.velocity.norm(), 0.0);
        origin[f.id] = {i, f.pixel};
      } else {
        ASSERT_EQ(previous[f.id].frame, i - 1) << "id " << f.id << " was not live in the previous frame";
        EXPECT_EQ(f.track_length, i - origin[f.id].frame + 1) << "id " << f.id;
        step_errors.push_back(cv::norm(cv::Point2d(f.pixel - previous[f.id].pixel) - step));
        const Eigen::Vector2d expected_velocity(step.x / 460 / 0.05, step.y / 460 / 0.05);
        velocity_errors.push_back((f.velocity - expected_velocity).norm() * 460 * 0.05);  // [px / frame]
        if (i == 19)
          drift.push_back(
              cv::norm(cv::Point2d(f.pixel) - (cv::Point2d(origin[f.id].pixel) + step * (i - origin[f.id].frame))));
      }
      previous[f.id] = {i, f.pixel};
    }
    if (i > 0) {
      EXPECT_GT(r.tracked, 100) << "frame " << i;
    }
  }
  ASSERT_GT(step_errors.size(), 1500u);
  EXPECT_LT(percentile(step_errors, 0.5), 0.05);
  EXPECT_LT(percentile(step_errors, 0.95), 0.1);
  EXPECT_LT(percentile(step_errors, 1.0), 0.5) << "within the forward-backward threshold";
  EXPECT_LT(percentile(velocity_errors, 0.95), 0.1);
  EXPECT_LT(percentile(drift, 0.5), 0.1) << "accumulated over up to 19 frames";
}

TEST(FeatureTracker, ReplenishmentFillsTheMaskButKeepsTheMinimumDistance) {
  const auto canvas = testing::texture(1000, 800, 2);
  FeatureTrackerConfig config = baseConfig();
  config.max_features = 150;
  config.min_distance = 30;
  // A detector that spaces its points as asked (as VINS-Mono's goodFeaturesToTrack(min_dist)) fills the budget;
  // one that does not (min distance 1 px) is thinned by the tracker.
  FeatureTracker spaced(pinhole(), std::make_shared<GfttDetector>(30.0), config);
  FeatureTracker tracker(pinhole(), std::make_shared<GfttDetector>(1.0), config);
  for (int i = 0; i < 5; ++i) {
    const cv::Mat image = testing::view(canvas, {4.0 * i, 0}, kSize);
    EXPECT_EQ(static_cast<int>(spaced.track(i * kFrameNs, image).features.size()), config.max_features) << i;
    const TrackingResult r = tracker.track(i * kFrameNs, image);
    EXPECT_GT(static_cast<int>(r.features.size()), 100) << "frame " << i;
    for (std::size_t a = 0; a < r.features.size(); ++a)
      for (std::size_t b = a + 1; b < r.features.size(); ++b)
        ASSERT_GE(cv::norm(r.features[a].pixel - r.features[b].pixel), config.min_distance - 1.0) << "frame " << i;
  }
}

// A camera translating along x past a 4x4 checkerboard of blocks at different depths (2 to 6 px/frame, all
// horizontal: one epipolar geometry; the speeds are shuffled so that no single plane, e.g. a tilted ground, explains
// them, which would leave the fundamental matrix undetermined); eight 80 px patches move on their own, each in another
// direction with at least 8 px/frame across the epipolar lines (independently moving objects). The RANSAC must drop
// their tracks. (With frame-to-frame motions of a few pixels a 1 px threshold leaves the epipolar geometry loose, so
// what RANSAC can catch are gross outliers; smaller independent motions may fit some other F.)
TEST(FeatureTracker, FundamentalRansacDropsIndependentlyMovingPoints) {
  const auto background = testing::texture(1200, 800, 3);
  const auto patch_texture = testing::texture(800, 600, 5);
  const std::vector<cv::Point> patches = {{40, 40},   {260, 60},  {520, 40},  {40, 290},
                                          {280, 200}, {520, 300}, {160, 390}, {420, 380}};
  const std::vector<cv::Point2d> motion = {{0, 9}, {6, -8}, {-6, 8}, {0, -9}, {5, 9}, {-5, -9}, {6, -8}, {-3, -9}};
  const int patch = 80;
  auto patchRect = [&](std::size_t k, int i, int margin) {
    return cv::Rect(static_cast<int>(patches[k].x + motion[k].x * i) + margin,
                    static_cast<int>(patches[k].y + motion[k].y * i) + margin, patch - 2 * margin, patch - 2 * margin);
  };
  auto frame = [&](int i) {
    cv::Mat image(kSize, CV_8UC1);
    const double speed[4][4] = {{2, 6, 3, 5}, {4.5, 2.5, 5.5, 3.5}, {6, 3, 2, 4}, {3.5, 5, 4, 2.5}};  // [px / frame]
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col)
        testing::paint(image, background, {speed[row][col] * i, 0}, cv::Rect(160 * col, 120 * row, 160, 120));
    for (std::size_t k = 0; k < patches.size(); ++k)
      testing::paint(image, patch_texture, motion[k] * i, patchRect(k, i, 0), {0, 0});
    return image;
  };
  FeatureTrackerConfig config = baseConfig();
  config.min_distance = 12;
  config.max_features = 300;
  FeatureTracker tracker(pinhole(), std::make_shared<GfttDetector>(12), config);
  int rejected = 0;
  for (int i = 0; i < 5; ++i) {
    const TrackingResult r = tracker.track(i * kFrameNs, frame(i));
    if (i == 0) continue;
    EXPECT_TRUE(r.ransac_run);
    rejected += r.rejected_ransac;
    for (const TrackedFeature& f : r.features) {
      if (f.track_length < 2) continue;
      for (std::size_t k = 0; k < patches.size(); ++k)
        // 15 px inside: the whole 21 px LK window lay on the patch in both frames (windows straddling its edge
        // mix the two motions and may look consistent)
        EXPECT_FALSE(patchRect(k, i, 15).contains(f.pixel))
            << "frame " << i << ": a track on moving patch " << k << " survived: id " << f.id << " at " << f.pixel
            << " moved " << (f.velocity * 0.05 * 460).transpose() << " ratio " << r.inlier_ratio << " rejected "
            << r.rejected_ransac << " tracked " << r.tracked;
    }
  }
  EXPECT_GT(rejected, 20);
}

// A textured board appears in front of part of the scene at frame 3: points there are occluded. Without the
// forward-backward check many of them are "tracked" onto the board; the check drops at least 90 % of those (a
// random texture can return a wrong match that also tracks back, so not always all).
// (Points within half a window of the board's edge are ambiguous and not counted.)
int wrongTracksAfterOcclusion(bool forward_backward) {
  const auto canvas = testing::texture(1000, 800, 6);
  const cv::Mat board = testing::view(testing::texture(640, 480, 7), {0, 0}, kSize, {0, 0});
  FeatureTrackerConfig config = baseConfig();
  config.ransac = false;  // attribute the rejections to the flow checks alone
  config.forward_backward = forward_backward;
  config.max_features = 200;
  config.min_distance = 15;
  FeatureTracker tracker(pinhole(), std::make_shared<GfttDetector>(15), config);
  std::map<std::uint64_t, cv::Point2f> previous;
  int wrong = 0;
  const cv::Rect occluder(160, 120, 320, 240);
  for (int i = 0; i < 5; ++i) {
    cv::Mat image = testing::view(canvas, {1.5 * i, 0.5 * i}, kSize);
    if (i >= 3) board(occluder).copyTo(image(occluder));
    const TrackingResult r = tracker.track(i * kFrameNs, image);
    for (const TrackedFeature& f : r.features) {
      // Points well inside the occluder (their whole LK window covered) that survive with a wrong position.
      const cv::Rect interior(occluder.x + 12, occluder.y + 12, occluder.width - 24, occluder.height - 24);
      if (i == 3 && previous.count(f.id) && interior.contains(previous[f.id]) &&
          cv::norm(f.pixel - (previous[f.id] + cv::Point2f(1.5f, 0.5f))) > 0.5)
        ++wrong;
      previous[f.id] = f.pixel;
    }
  }
  return wrong;
}

TEST(FeatureTracker, ForwardBackwardCheckDropsOccludedPoints) {
  const int without = wrongTracksAfterOcclusion(false), with = wrongTracksAfterOcclusion(true);
  EXPECT_GT(without, 10) << "the test scene must produce wrong tracks without the check";
  EXPECT_LE(with, without / 10) << "without the check: " << without;
}

TEST(FeatureTracker, SynchronousModeIsDeterministic) {
  const auto canvas = testing::texture(1000, 800, 8);
  FeatureTracker a(pinhole(), std::make_shared<GfttDetector>(), baseConfig());
  FeatureTracker b(pinhole(), std::make_shared<GfttDetector>(), baseConfig());
  for (int i = 0; i < 6; ++i) {
    const cv::Mat image = testing::view(canvas, {3.1 * i, 1.2 * i}, kSize);
    const TrackingResult ra = a.track(i * kFrameNs, image), rb = b.track(i * kFrameNs, image);
    ASSERT_EQ(ra.features.size(), rb.features.size());
    for (std::size_t k = 0; k < ra.features.size(); ++k) {
      EXPECT_EQ(ra.features[k].id, rb.features[k].id);
      EXPECT_EQ(ra.features[k].pixel, rb.features[k].pixel);
    }
  }
}

// A slow detector (60 ms) in the worker while frames arrive every 25 ms: its points, found in frame k, are added at
// a later frame j, carried there by the flow: each lies within 0.5 px (median 0.1 px) of where the detected point
// moved to (its position in frame k + (j - k) steps).
TEST(FeatureTracker, AsyncDetectionAddsPointsCarriedToTheCurrentFrame) {
  const auto canvas = testing::texture(1000, 800, 9);
  FeatureTrackerConfig config = baseConfig();
  config.async_detection = true;
  config.max_features = 400;  // more than the texture yields at 30 px: the tracker keeps asking for points
  auto detector = std::make_shared<GfttDetector>(30, 60);
  FeatureTracker tracker(pinhole(), detector, config);
  const cv::Point2d step(2.0, 1.0);
  std::vector<cv::Mat> frames;
  std::vector<std::pair<int, cv::Point2f>> added_later;  // (frame, pixel)
  for (int i = 0; i < 12; ++i) {
    frames.push_back(testing::view(canvas, step * i, kSize));
    const TrackingResult r = tracker.track(i * kFrameNs, frames.back());
    for (const TrackedFeature& f : r.features)
      if (i > 0 && f.track_length == 1) added_later.emplace_back(i, f.pixel);
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  ASSERT_GT(added_later.size(), 0u) << "the worker's detections were added";
  std::vector<double> errors;
  const std::lock_guard<std::mutex> lock(detector->mutex);
  for (const auto& [j, pixel] : added_later) {
    double best = 1e9;  // distance to the nearest detection of an earlier frame, moved to frame j
    for (const auto& [image, points] : detector->history) {
      int k = 0;
      while (k < j && cv::norm(frames[k], image, cv::NORM_INF) != 0) ++k;
      if (k == j) continue;
      for (const cv::Point2f& q : points)
        best = std::min(best, cv::norm(cv::Point2d(pixel) - (cv::Point2d(q) + step * (j - k))));
    }
    errors.push_back(best);
  }
  EXPECT_LT(percentile(errors, 0.5), 0.1);
  EXPECT_LT(percentile(errors, 1.0), 0.5);
}

// Live tracking (async detection): a pass in the worker lands a frame or two later, and where tracks die fast the
// VIS ran out of them first. Below detect_sync_below Shi-Tomasi corners fill the frame itself. Here a cut keeps only
// the top-left 200 x 200 px of the view, so a few tracks live on: with the threshold that frame gets corners at
// once; without it nothing, until the worker's pass (500 ms here) lands. The frames are rendered before tracking:
// rendering them between the calls took ~150 ms a frame on one machine, and the pass had landed by the cut (frames
// 1-3 track in ~50 ms together).
TEST(FeatureTracker, BelowDetectSyncBelowAnAsyncTrackerDetectsOnTheFrameItself) {
  const auto canvas = testing::texture(1000, 800, 9);
  const auto other = testing::texture(1000, 800, 5);
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 4; ++i) frames.push_back(testing::view(canvas, {2.0 * i, 0}, kSize));
  const cv::Rect kept(0, 0, 200, 200);
  cv::Mat mixed = testing::view(other, {0, 0}, kSize).clone();
  frames[3](kept).copyTo(mixed(kept));
  frames[3] = mixed;
  const auto cutFrame = [&](int sync_below) {
    FeatureTrackerConfig config = baseConfig();
    config.async_detection = true;
    config.detect_sync_below = sync_below;
    FeatureTracker tracker(pinhole(), std::make_shared<GfttDetector>(30, 500), config);
    TrackingResult cut;
    for (int i = 0; i < 4; ++i) {
      const TrackingResult r = tracker.track(i * kFrameNs, frames[i]);
      if (i == 3) cut = r;
    }
    return cut;
  };
  const TrackingResult with = cutFrame(60), without = cutFrame(0);
  ASSERT_GT(with.tracked, 0) << "some tracks live through the cut";
  ASSERT_LT(with.tracked, 60);
  ASSERT_EQ(without.tracked, with.tracked) << "the same frames and tracks up to the cut";
  EXPECT_GT(with.added_corners, 20) << "corners on the cut frame itself";
  EXPECT_EQ(with.added, with.added_corners) << "the worker's pass has not landed yet";
  EXPECT_EQ(without.added, 0) << "the worker's pass has not landed yet";
}

// Detect-when-needed (the VIS's policy for SuperPoint): with detect_below the detector runs only when the live tracks
// fall below it; on a texture sliding out of view, tracks are lost at the leading edge, so the detector runs on some
// frames and not on others, and never while the count is at or above the threshold.
TEST(FeatureTracker, DetectBelowRunsTheDetectorOnlyWhenTheLiveTracksFallBelowIt) {
  const auto canvas = testing::texture(1400, 800, 5);
  FeatureTrackerConfig config = baseConfig();
  config.detect_below = 90;
  FeatureTracker tracker(pinhole(), std::make_shared<GfttDetector>(), config);
  int detected = 0, skipped = 0;
  std::size_t previous = 0;
  for (int i = 0; i < 40; ++i) {
    const TrackingResult r = tracker.track(i * kFrameNs, testing::view(canvas, {12.0 * i, 0}, kSize));
    const int before = r.tracked;  // live tracks before replenishment
    if (i > 0 && before >= config.detect_below) {
      EXPECT_EQ(r.added, 0) << "frame " << i << ": " << before << " live tracks";
      ++skipped;
    }
    if (r.added > 0) ++detected;
    previous = r.features.size();
  }
  EXPECT_GT(detected, 1);
  EXPECT_GT(skipped, 5);
  EXPECT_GT(previous, 60u);
}

// A slow detector that never fills the window (SuperPoint on plain walls) is held to one run per detect_interval_s
// of image time, except when the live tracks fall below detect_urgent_below: here a texture sliding 12 px a frame
// loses tracks at every frame (so detect_below alone would detect at every frame), and a cut to another texture at
// frame 21 loses them all.
TEST(FeatureTracker, DetectIntervalHoldsASlowDetectorToOneRunPerIntervalUnlessTracksRunOut) {
  const auto canvas = testing::texture(1400, 800, 5);
  const auto other = testing::texture(1400, 800, 9);
  FeatureTrackerConfig config = baseConfig();
  config.detect_interval_s = 0.2;  // 4 frames at 20 Hz
  config.detect_urgent_below = 30;
  const auto detector = std::make_shared<GfttDetector>();
  detector->slow = true;
  FeatureTracker tracker(pinhole(), detector, config);
  std::vector<int> ran;
  for (int i = 0; i < 30; ++i) {
    const int before = detector->calls;
    const TrackingResult r = tracker.track(i * kFrameNs, testing::view(i < 21 ? canvas : other, {12.0 * i, 0}, kSize));
    if (detector->calls > before) ran.push_back(i);
    if (i == 21) {
      EXPECT_LT(r.tracked, config.detect_urgent_below) << "the cut must lose the tracks";
    }
  }
  EXPECT_EQ(ran, (std::vector<int>{0, 4, 8, 12, 16, 20, 21, 25, 29}));
  FeatureTrackerConfig every = baseConfig();
  const auto plain = std::make_shared<GfttDetector>();
  FeatureTracker without(pinhole(), plain, every);
  for (int i = 0; i < 30; ++i) without.track(i * kFrameNs, testing::view(canvas, {12.0 * i, 0}, kSize));
  EXPECT_EQ(plain->calls, 30) << "without the interval the detector runs at every frame here";
  // A millisecond detector ignores the pacing: the same interval config, a detector that is not paced.
  const auto fast = std::make_shared<GfttDetector>();
  FeatureTracker unpaced(pinhole(), fast, config);
  for (int i = 0; i < 30; ++i) unpaced.track(i * kFrameNs, testing::view(canvas, {12.0 * i, 0}, kSize));
  EXPECT_EQ(fast->calls, 30) << "the pacing holds only a paced detector";
}

TEST(FeatureTracker, RejectsBadConfigImagesAndTimes) {
  FeatureTrackerConfig bad = baseConfig();
  bad.flow_window = 20;
  EXPECT_NE(bad.validate().find("flow_window"), std::string::npos);
  FeatureTrackerConfig bad_eigenvalue = baseConfig();
  bad_eigenvalue.min_eigenvalue = -1e-3;
  EXPECT_NE(bad_eigenvalue.validate().find("min_eigenvalue"), std::string::npos);
  FeatureTrackerConfig bad_interval = baseConfig();
  bad_interval.detect_interval_s = -0.1;
  EXPECT_NE(bad_interval.validate().find("detect_interval_s"), std::string::npos);
  bad_interval.detect_interval_s = 0.5;
  bad_interval.detect_urgent_below = -1;
  EXPECT_NE(bad_interval.validate().find("detect_urgent_below"), std::string::npos);
  EXPECT_THROW(FeatureTracker(pinhole(), std::make_shared<GfttDetector>(), bad), std::invalid_argument);
  EXPECT_THROW(FeatureTracker(pinhole(), nullptr, baseConfig()), std::invalid_argument);
  FeatureTracker tracker(pinhole(), std::make_shared<GfttDetector>(), baseConfig());
  EXPECT_THROW(tracker.track(0, cv::Mat(100, 100, CV_8UC1)), std::invalid_argument);
  const cv::Mat image = testing::view(testing::texture(640, 480, 1), {0, 0}, kSize, {0, 0});
  tracker.track(10, image);
  EXPECT_THROW(tracker.track(10, image), std::invalid_argument);
}

// A texture sliding 7 px a frame: features leave the image on one side (and a few fail the forward-backward check
// near it). Every ended track is listed once with its length and its cause, and the per-cause lists agree with the
// frame's counters.
TEST(FeatureTracker, EveryEndedTrackIsRecordedOnceWithItsCause) {
  const auto canvas = testing::texture(1200, 600, 8);
  FeatureTracker tracker(pinhole(), std::make_shared<GfttDetector>(30), baseConfig());
  int leaving = 0, counted = 0, finished = 0;
  for (int i = 0; i < 12; ++i) {
    const TrackingResult r = tracker.track(i * kFrameNs, testing::view(canvas, {7.0 * i, 0.0}, kSize));
    ASSERT_EQ(r.finished_causes.size(), r.finished_lengths.size());
    std::map<TrackEnd, int> by;
    for (TrackEnd e : r.finished_causes) ++by[e];
    EXPECT_EQ(by[TrackEnd::kLostFlow], r.lost_flow) << i;
    EXPECT_EQ(by[TrackEnd::kForwardBackward], r.rejected_fb) << i;
    EXPECT_EQ(by[TrackEnd::kBorder], r.rejected_border) << i;
    EXPECT_EQ(by[TrackEnd::kRansac], r.rejected_ransac) << i;
    EXPECT_EQ(by[TrackEnd::kCrowded], r.dropped_crowded) << i;
    // A point whose LK window leaves the image gets status 0 from OpenCV (lost flow) before the border check
    // sees it, so leaving the image counts under either.
    leaving += r.lost_flow + r.rejected_border;
    counted += r.lost_flow + r.rejected_fb + r.rejected_border + r.rejected_ransac + r.dropped_crowded;
    finished += static_cast<int>(r.finished_lengths.size());
  }
  EXPECT_GT(leaving, 4) << "tracks leave the image as the texture slides";
  EXPECT_EQ(finished, counted) << "every ended track has exactly one cause";
  EXPECT_STREQ(trackEndName(TrackEnd::kForwardBackward), "rejected_fb");
  EXPECT_STREQ(trackEndName(TrackEnd::kCrowded), "dropped_crowded");
}

// 95 real frames of EuRoC V1_01 (752x480, 20 Hz, rad-tan lens) through the reader: tracks live for many frames,
// RANSAC keeps most of them, the budget stays nearly full.
TEST(FeatureTracker, OnEurocFramesTracksAreLongAndMostlyInliers) {
  const auto path = test::sharedData("euroc/V1_01_easy_micro");
  DROVER_REQUIRE_SHARED(path / "mav0/cam0/data");
  io::DatasetOptions options;
  options.load_imu = false;
  options.load_lidar = false;
  const auto reader = io::openDataset(path.string(), "euroc", options);
  FeatureTracker tracker(CameraModel(reader->calibration().camera), std::make_shared<GfttDetector>(30),
                         FeatureTrackerConfig{});
  std::vector<int> finished;
  double inlier_sum = 0, features_sum = 0;
  int frames = 0, ransac_frames = 0;
  while (auto m = reader->next()) {
    const auto* frame = std::get_if<CameraFrame>(&*m);
    if (!frame) continue;
    const TrackingResult r = tracker.track(frame->t, imageView(frame->image));
    finished.insert(finished.end(), r.finished_lengths.begin(), r.finished_lengths.end());
    features_sum += static_cast<double>(r.features.size());
    if (r.ransac_run) {
      inlier_sum += r.inlier_ratio;
      ++ransac_frames;
    }
    ++frames;
  }
  ASSERT_GE(frames, 90);
  ASSERT_GT(finished.size(), 20u);
  double mean_length = 0;
  for (int l : finished) mean_length += l;
  mean_length /= static_cast<double>(finished.size());
  EXPECT_GT(mean_length, 6.0);
  EXPECT_LT(mean_length, 95.0);
  EXPECT_GT(inlier_sum / ransac_frames, 0.85);
  EXPECT_GT(features_sum / frames, 120.0);
  std::printf("EuRoC: %d frames, %.1f features/frame, mean finished track length %.1f, inlier ratio %.3f\n", frames,
              features_sum / frames, mean_length, inlier_sum / ransac_frames);
}

}  // namespace
}  // namespace drover::visual
