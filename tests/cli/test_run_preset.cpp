// drover run --preset / --without on the visual side: what each leaves of the platform's LK threshold. The drover
// preset holds SuperPoint's tracks to a smallest gradient eigenvalue of 2e-3 (LK slides along the edges SuperPoint
// keeps on plain walls); Shi-Tomasi's corners are picked by that eigenvalue already and keep the platform's value;
// the lvi-sam preset takes OpenCV's default, as LVI-SAM's tracker does.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace drover::cli
