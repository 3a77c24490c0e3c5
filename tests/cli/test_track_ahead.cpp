// cli::TrackAhead, the VIS's front end running ahead of `drover run`'s replay: its tracks are the ones a tracker
// in the caller's thread makes from the same frames, bit for bit; a bad frame's error comes back with that frame and
// the frames after it are tracked as if it had not been there; a frame taken out of order is a logic error; and it
// stops cleanly with frames still queued.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "apps/drover/track_ahead.hpp"
#include "visual/camera_model.hpp"
#include "visual/detector_factory.hpp"

namespace drover::cli {
namespace {

constexpr Time kFrameNs = 66'666'667;  // 15 Hz

Calibration camera640() {
  Calibration c;
  c.camera.width = 640;
  c.camera.height = 480;
  c.camera.fx = c.camera.fy = 460;
  c.camera.cx = 319.5;
  c.camera.cy = 239.5;
  c.camera_time_offset = 5'000'000;  // 5 ms: the tracks carry the corrected stamp
  return c;
}

// A smooth random texture (blurred noise) shifted 3 px right and 1 px down a frame.
CameraFrame frame(int k, int width = 640, int height = 480) {
  static const cv::Mat canvas = [] {
    cv::Mat noise(700, 900, CV_8UC1);
    cv::RNG rng(7);
    rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
    cv::GaussianBlur(noise, noise, cv::Size(0, 0), 2.5);
    cv::normalize(noise, noise, 0, 255, cv::NORM_MINMAX);
    return noise;
  }();
  const cv::Mat view = canvas(cv::Rect(3 * k, k, std::min(width, 900 - 3 * k), std::min(height, 700 - k))).clone();
  CameraFrame f;
  f.t = k * kFrameNs;
  f.image.width = view.cols;
  f.image.height = view.rows;
  f.image.channels = 1;
  f.image.data.assign(view.data, view.data + view.total());
  return f;
}

visual::FeatureTrackerConfig trackerConfig() {
  visual::FeatureTrackerConfig c;
  c.max_features = 120;
  c.min_distance = 20;
  return c;
}

std::shared_ptr<visual::KeypointDetector> shiTomasi() {
  visual::DetectorConfig d;
  d.type = visual::DetectorType::kShiTomasi;
  return visual::makeDetector(d);
}

void expectSameTracks(const visual::TrackingResult& a, const visual::TrackingResult& b) {
  ASSERT_EQ(a.t, b.t);
  ASSERT_EQ(a.features.size(), b.features.size());
  EXPECT_EQ(a.added, b.added);
  for (std::size_t i = 0; i < a.features.size(); ++i) {
    EXPECT_EQ(a.features[i].id, b.features[i].id);
    EXPECT_EQ(a.features[i].pixel, b.features[i].pixel);
    EXPECT_EQ(a.features[i].normalized, b.features[i].normalized);
  }
}

TEST(TrackAhead, GivesTheTracksOfATrackerInTheCallersThreadAndKeepsGoingPastABadFrame) {
  const Calibration calibration = camera640();
  visual::FeatureTracker plain(visual::CameraModel(calibration.camera), shiTomasi(), trackerConfig());
  TrackAhead ahead(calibration, shiTomasi(), trackerConfig());
  std::vector<CameraFrame> frames;
  for (int k = 0; k < 24; ++k) frames.push_back(k == 9 ? frame(k, 320, 240) : frame(k));  // frame 9: wrong size
  std::size_t submitted = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    while (submitted < frames.size() && submitted < k + 3) ahead.submit(frames[submitted++]);  // 3 ahead
    if (k == 9) {
      EXPECT_THROW(ahead.take(frames[k]), std::invalid_argument);
      continue;  // as drover run skips it: the plain tracker never sees it either
    }
    const visual::TrackingResult expected =
        plain.track(frames[k].t + calibration.camera_time_offset, visual::imageView(frames[k].image));
    ASSERT_NO_FATAL_FAILURE(expectSameTracks(ahead.take(frames[k]), expected)) << "frame " << k;
    if (k == 23) {
      EXPECT_GT(expected.features.size(), 50u) << "the texture must be trackable for this to test much";
      EXPECT_GT(expected.tracked, 50) << "and tracked from frame to frame";
    }
  }
}

TEST(TrackAhead, AFrameTakenOutOfOrderOrNeverSubmittedIsALogicError) {
  TrackAhead ahead(camera640(), shiTomasi(), trackerConfig());
  EXPECT_THROW(ahead.take(frame(0)), std::logic_error);
  ahead.submit(frame(0));
  ahead.submit(frame(1));
  EXPECT_THROW(ahead.take(frame(1)), std::logic_error);
}

TEST(TrackAhead, StopsWithFramesStillQueued) {
  auto ahead = std::make_unique<TrackAhead>(camera640(), shiTomasi(), trackerConfig());
  for (int k = 0; k < 10; ++k) ahead->submit(frame(k));
  ahead.reset();  // must join, not hang
  SUCCEED();
}

}  // namespace
}  // namespace drover::cli
