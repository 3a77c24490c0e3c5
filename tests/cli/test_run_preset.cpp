// drover run --preset / --without on the VIS's settings: what each leaves of the platform's LK threshold, keyframe
// interval and corner top-up. The drover preset holds SuperPoint's tracks to a smallest gradient eigenvalue of 2e-3 (LK slides along the edges SuperPoint
// keeps on plain walls); Shi-Tomasi's corners are picked by that eigenvalue already and keep the platform's value;
// the lvi-sam preset takes OpenCV's default, as LVI-SAM's tracker does.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "apps/drover/run_preset.hpp"

namespace drover::cli {
namespace {

// The LK threshold a run gets from a platform config with `detector` and `platform_threshold`.
double thresholdAfter(const MethodChoice& method, visual::DetectorType detector, double platform_threshold) {
  io::VisualConfig visual;
  vio::VioConfig vio;
  visual.detector.type = detector;
  visual.tracker.min_eigenvalue = platform_threshold;
  method.apply(visual, vio);
  return visual.tracker.min_eigenvalue;
}

constexpr auto kSuperPoint = visual::DetectorType::kSuperPoint;
constexpr auto kShiTomasi = visual::DetectorType::kShiTomasi;

TEST(RunPreset, TheDroverPresetHoldsSuperPointTracksToAMinimumEigenvalueOf2e3) {
  EXPECT_DOUBLE_EQ(thresholdAfter({Preset::kDrover, {}}, kSuperPoint, 1e-4), 2e-3);
  EXPECT_DOUBLE_EQ(thresholdAfter({Preset::kDrover, {}}, kShiTomasi, 1e-4), 2e-3)
      << "the preset's own detector is SuperPoint, whatever the platform file names";
  EXPECT_DOUBLE_EQ(thresholdAfter({Preset::kDrover, {}}, kSuperPoint, 5e-3), 5e-3) << "a stricter platform stays";
}

TEST(RunPreset, WithoutSuperPointOrWithoutTheThresholdTheTracksKeepThePlatformsValue) {
  EXPECT_DOUBLE_EQ(thresholdAfter({Preset::kDrover, {"superpoint"}}, kSuperPoint, 1e-4), 1e-4);
  EXPECT_DOUBLE_EQ(thresholdAfter({Preset::kDrover, {"lk-min-eigenvalue"}}, kSuperPoint, 1e-4), 1e-4);
  EXPECT_DOUBLE_EQ(thresholdAfter({Preset::kDrover, {"lk-min-eigenvalue"}}, kSuperPoint, 3e-4), 3e-4);
}

TEST(RunPreset, TheLviSamPresetUsesOpenCvsDefaultAndThePlatformPresetChangesNothing) {
  EXPECT_DOUBLE_EQ(thresholdAfter({Preset::kLviSam, {}}, kSuperPoint, 2e-3), 1e-4);
  EXPECT_DOUBLE_EQ(thresholdAfter({Preset::kPlatform, {}}, kSuperPoint, 7e-4), 7e-4);
}

// The VIS's keyframes: the drover preset adds one every 0.5 s where parallax makes none (unless the platform sets its
// own interval), the lvi-sam preset and --without keyframe-interval keep VINS-Mono's parallax rule.
double intervalAfter(const MethodChoice& method, double platform_interval) {
  io::VisualConfig visual;
  vio::VioConfig vio;
  vio.max_keyframe_interval_s = platform_interval;
  method.apply(visual, vio);
  return vio.max_keyframe_interval_s;
}

TEST(RunPreset, TheDroverPresetMakesAKeyframeEveryHalfSecondWithoutParallaxAndLviSamOnlyByParallax) {
  EXPECT_DOUBLE_EQ(intervalAfter({Preset::kDrover, {}}, 0), 0.5);
  EXPECT_DOUBLE_EQ(intervalAfter({Preset::kDrover, {}}, 1.0), 1.0) << "a platform's own interval stays";
  EXPECT_DOUBLE_EQ(intervalAfter({Preset::kDrover, {"keyframe-interval"}}, 1.0), 0);
  EXPECT_DOUBLE_EQ(intervalAfter({Preset::kLviSam, {}}, 1.0), 0);
  EXPECT_DOUBLE_EQ(intervalAfter({Preset::kPlatform, {}}, 0.7), 0.7);
}

// The corner top-up is a platform setting: the presets keep it as the platform file sets it (off in the shipped
// files; in the drover preset it failed the farm's fault course), and Shi-Tomasi runs (lvi-sam, --without
// superpoint) never top up, being the corners already.
visual::FeatureTrackerConfig trackerAfter(const MethodChoice& method, visual::DetectorType detector) {
  io::VisualConfig visual;
  vio::VioConfig vio;
  visual.detector.type = detector;
  visual.tracker.top_up_below = 40;
  visual.tracker.top_up_min_eigenvalue = 5e-4;
  visual.tracker.detect_sync_below = 20;
  method.apply(visual, vio);
  return visual.tracker;
}

TEST(RunPreset, ThePresetsKeepThePlatformsCornerTopUpExceptForShiTomasi) {
  const visual::FeatureTrackerConfig drover = trackerAfter({Preset::kDrover, {}}, kSuperPoint);
  EXPECT_EQ(drover.top_up_below, 40);
  EXPECT_DOUBLE_EQ(drover.top_up_min_eigenvalue, 5e-4) << "the platform file's floor for the corners";
  EXPECT_DOUBLE_EQ(drover.min_eigenvalue, 2e-3);
  EXPECT_EQ(trackerAfter({Preset::kDrover, {"superpoint"}}, kSuperPoint).top_up_below, 0);
  EXPECT_EQ(trackerAfter({Preset::kLviSam, {}}, kSuperPoint).top_up_below, 0);
  EXPECT_EQ(trackerAfter({Preset::kPlatform, {}}, kSuperPoint).top_up_below, 40);
  EXPECT_EQ(trackerAfter({Preset::kPlatform, {}}, kShiTomasi).top_up_below, 0);
  // The live corners where SuperPoint's worker is late: kept with SuperPoint, not for a Shi-Tomasi detector.
  EXPECT_EQ(drover.detect_sync_below, 20);
  EXPECT_EQ(trackerAfter({Preset::kDrover, {"superpoint"}}, kSuperPoint).detect_sync_below, 0);
  EXPECT_EQ(trackerAfter({Preset::kLviSam, {}}, kSuperPoint).detect_sync_below, 0);
}

// The keyframe gap's speed rule: the drover preset waives a gap while the VIS holds the IMU's speed within 0.2 m/s
// (+ 5 %); the platform keeps every gap a stall (its VIS can coast on sliding tracks), --without keyframe-gap-speed
// restores that in the preset, and the lvi-sam preset has no keyframe gate at all.
pipeline::VisualMotionConfig fusionAfter(const MethodChoice& method, double platform_tolerance) {
  pipeline::OdometryConfig odometry;
  odometry.vis_fusion.keyframe_gap_velocity_tolerance = platform_tolerance;
  method.apply(odometry);
  return odometry.vis_fusion;
}

TEST(RunPreset, TheDroverPresetCountsAKeyframeGapAsAStallOnlyWhenTheVisVelocityLeftTheImus) {
  EXPECT_DOUBLE_EQ(fusionAfter({Preset::kDrover, {}}, 0).keyframe_gap_velocity_tolerance, 0.2);
  EXPECT_DOUBLE_EQ(fusionAfter({Preset::kDrover, {"keyframe-gap-speed"}}, 0).keyframe_gap_velocity_tolerance, 0);
  EXPECT_DOUBLE_EQ(fusionAfter({Preset::kPlatform, {}}, 0.3).keyframe_gap_velocity_tolerance, 0.3);
  EXPECT_DOUBLE_EQ(pipeline::VisualMotionConfig{}.keyframe_gap_velocity_tolerance, 0) << "the platform's default";
  EXPECT_GT(fusionAfter({Preset::kLviSam, {}}, 0).max_keyframe_gap, 1e9) << "no keyframe gate";
}

// The scan match's attitude in the IMU smoother: the drover preset holds it at 0.01 rad (LIO-SAM's 0.05 lets the
// smoother's pitch ride on the accelerometer bias along a degenerate corridor) except on degenerate sweeps that no
// relative factor aids; a tighter platform value stays, and the lvi-sam preset and --without lidar-rotation-sigma
// keep the platform's.
double lidarRotationSigmaAfter(const MethodChoice& method, double platform_sigma, double* unaided = nullptr) {
  pipeline::OdometryConfig odometry;
  odometry.lidar_sigma_rotation = platform_sigma;
  method.apply(odometry);
  if (unaided != nullptr) *unaided = odometry.lidar_sigma_rotation_unaided;
  return odometry.lidar_sigma_rotation;
}

TEST(RunPreset, TheDroverPresetHoldsTheScanMatchsAttitudeToOneHundredthOfARadian) {
  double unaided = 0;
  EXPECT_DOUBLE_EQ(lidarRotationSigmaAfter({Preset::kDrover, {}}, 0.05, &unaided), 0.01);
  EXPECT_DOUBLE_EQ(unaided, 0.05) << "a degenerate sweep without the VIS's factor keeps the platform's sigma";
  EXPECT_DOUBLE_EQ(lidarRotationSigmaAfter({Preset::kDrover, {}}, 0.002), 0.002) << "a tighter platform stays";
  EXPECT_DOUBLE_EQ(lidarRotationSigmaAfter({Preset::kDrover, {"lidar-rotation-sigma"}}, 0.05), 0.05);
  EXPECT_DOUBLE_EQ(lidarRotationSigmaAfter({Preset::kLviSam, {}}, 0.05), 0.05) << "LIO-SAM's correction noise";
  EXPECT_DOUBLE_EQ(lidarRotationSigmaAfter({Preset::kPlatform, {}}, 0.05), 0.05);
  const std::vector<std::string> parts = partNames();
  EXPECT_NE(std::find(parts.begin(), parts.end(), "lidar-rotation-sigma"), parts.end()) << "an ablation row";
}

// The scan matcher's degeneracy test: the lvi-sam preset keeps LIO-SAM's fixed eigenvalue threshold alone; the
// drover preset and the platform file keep the platform's per-correspondence threshold.
double perCorrespondenceAfter(const MethodChoice& method) {
  pipeline::OdometryConfig odometry;
  odometry.matcher.degeneracy_threshold_per_correspondence = 0.03;
  method.apply(odometry);
  return odometry.matcher.degeneracy_threshold_per_correspondence;
}

TEST(RunPreset, TheLviSamPresetTestsDegeneracyWithLioSamsFixedThresholdAlone) {
  EXPECT_DOUBLE_EQ(perCorrespondenceAfter({Preset::kLviSam, {}}), 0.0);
  EXPECT_DOUBLE_EQ(perCorrespondenceAfter({Preset::kDrover, {}}), 0.03);
  EXPECT_DOUBLE_EQ(perCorrespondenceAfter({Preset::kPlatform, {}}), 0.03);
}

}  // namespace
}  // namespace drover::cli
