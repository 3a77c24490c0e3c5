// LK tracks on the simulator's rendered frames against the exact image motion. A brick wall 8 m ahead (mortar 1.5 cm,
// 0.86 px there) slides sideways across the view at a known sub-pixel rate. With one ray through each pixel's centre
// the texture finer than a pixel aliases, and the sampled pattern shimmers as it moves by fractions of a pixel,
// which LK reads as motion: chained tracks drift. With 2x2 rays over the pixel's area (as a sensor pixel integrates
// the light falling on it; sim::CameraModelConfig::pixel_samples) they drift less. The tracks are chained frame to
// frame with the tracker's LK settings, as visual::FeatureTracker chains them.
#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "sim/camera_model.hpp"
#include "sim/world.hpp"
#include "support/camera_scene.hpp"
#include "visual/feature_tracker.hpp"

namespace drover::sim {
namespace {

constexpr double kWallDistance = 8.0;  // [m]
constexpr double kShiftPx = 0.37;      // [px] image motion a frame (sub-pixel, not a simple fraction)
constexpr int kChainFrames = 16;            // 15 chained steps
constexpr double kFrameS = 1.0 / 15;   // [s]

World brickWall() {
  Material brick;
  brick.texture = Texture::kBrick;
  brick.albedo = Eigen::Vector3f(0.7f, 0.4f, 0.3f);
  return test::wallWorld(kWallDistance, brick, 30);
}

// Body x forward, y left, z up; the camera looks along x. The body slides to its right (-y) so that the wall's image
// moves left by kShiftPx a frame: fx dy / Z.
SplineTrajectory slidingTrajectory(double fx) {
  const double speed = kShiftPx * kWallDistance / (fx * kFrameS);  // [m/s]
  std::vector<PathSample> samples;
  for (int i = 0; i <= 30; ++i) {
    PathSample s;
    s.t = fromSeconds(0.1 * i);
    s.p_world = Eigen::Vector3d(0, -speed * 0.1 * i, 0);
    samples.push_back(s);
  }
  return SplineTrajectory(samples);
}

// Median distance [px] after 15 chained LK steps between each track and where the wall's motion puts it.
double medianDriftPx(int pixel_samples) {
  CameraModelConfig config;
  config.noise = false;
  config.intrinsics.distortion = DistortionModel::kNone;  // the image motion is one shift everywhere
  config.intrinsics.distortion_coeffs.clear();
  config.pixel_samples = pixel_samples;
  const CameraRenderer camera(config);
  const World world = brickWall();
  const SplineTrajectory trajectory = slidingTrajectory(config.intrinsics.fx);
  std::vector<cv::Mat> frames;
  for (int k = 0; k < kChainFrames; ++k) {
    const CameraFrame f =
        camera.render(world, trajectory, test::forwardCamera(), {}, fromSeconds(0.5 + k * kFrameS), 1, k);
    frames.push_back(cv::Mat(f.image.height, f.image.width, CV_8UC1, const_cast<std::uint8_t*>(f.image.data.data()))
                         .clone());
  }
  const visual::FeatureTrackerConfig tracker;
  std::vector<cv::Point2f> start;
  for (int v = 140; v <= 340; v += 20)
    for (int u = 220; u <= 420; u += 20) start.emplace_back(static_cast<float>(u), static_cast<float>(v));
  std::vector<cv::Point2f> at = start;
  std::vector<bool> alive(start.size(), true);
  for (int k = 1; k < kChainFrames; ++k) {
    std::vector<cv::Point2f> next;
    std::vector<uchar> status;
    std::vector<float> error;
    cv::calcOpticalFlowPyrLK(frames[static_cast<std::size_t>(k - 1)], frames[static_cast<std::size_t>(k)], at, next,
                             status, error, cv::Size(tracker.flow_window, tracker.flow_window), tracker.flow_levels,
                             cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                              tracker.flow_iterations, tracker.flow_epsilon));
    for (std::size_t i = 0; i < at.size(); ++i) alive[i] = alive[i] && status[i] != 0;
    at = next;
  }
  std::vector<double> drift;
  for (std::size_t i = 0; i < start.size(); ++i) {
    if (!alive[i]) continue;
    const cv::Point2f truth(start[i].x - static_cast<float>(kShiftPx * (kChainFrames - 1)), start[i].y);
    drift.push_back(cv::norm(at[i] - truth));
  }
  EXPECT_GE(drift.size(), start.size() * 9 / 10) << "tracks lost";
  if (drift.empty()) return 1e9;
  std::nth_element(drift.begin(), drift.begin() + static_cast<std::ptrdiff_t>(drift.size() / 2), drift.end());
  return drift[drift.size() / 2];
}

TEST(RenderedTrackDrift, TwoByTwoRaysAPixelCutTheDriftOfLkTracksChainedOverABrickWallMovingSubPixel) {
  const double one = medianDriftPx(1), area = medianDriftPx(2);
  std::printf("median drift after 15 frames: %.3f px with one ray a pixel, %.3f px with 2x2\n", one, area);
  EXPECT_GT(one, 0.3) << "point-sampled bricks at 8 m alias";
  EXPECT_LT(area, 0.3 * one);  // measured 0.94 and 0.11 px
}

}  // namespace
}  // namespace drover::sim
