// With SuperPoint, the corridor's VIS re-initialised after the textureless stretch tilts itself 0.77 deg within its
// warm-up while keeping the LIS's accelerometer bias: 0.13 m/s^2 of gravity it reads as acceleration along the
// corridor. Fused, it ran from 0.97 to 1.4 m/s in 2.6 s at a steady 1.0 m/s and the degenerate LIS with it (the
// `drover run` replay drifted 19.7 % over the 38 m). The one-sweep gates cannot see it: they compare the VIS with the
// IMU's prediction from the LIS's newest state, which the VIS has already pulled. The VIS's and the LIS's attitude
// and accelerometer bias can: they make different accelerations of the same specific force
// (vis_fusion.max_acceleration_difference), so the VIS is refused from its first sweep and reset. Needs the
// pretrained SuperPoint of ../shared/models; ~55 s on two cores.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "support/fused_run.hpp"
#include "support/shared_data.hpp"

namespace drover {
namespace {

TEST(SimVisTiltRefusal, ATiltedReinitialisedSuperPointVisIsRefusedBeforeItPullsTheLisAlongTheCorridor) {
  const std::filesystem::path model = test::sharedDir() / "models" / "superpoint_v1.onnx";
  DROVER_REQUIRE_SHARED(model);
  constexpr Time kS = 1'000'000'000;
  const test::LiveCourse course =
      test::simulateLiveCourse("corridor", 0, 1, true,
                               {{sim::FaultKind::kCameraBlackout, 5 * kS, 10 * kS},
                                {sim::FaultKind::kLidarDropout, 13 * kS, 16 * kS},
                                {sim::FaultKind::kImuGap, 18 * kS, 18 * kS + kS / 2},
                                {sim::FaultKind::kTextureless, 21 * kS, 26 * kS}});
  const test::FusedRun r = test::runFused(course, 0, true, {}, {}, [&](visual::DetectorConfig& d) {
    d.type = visual::DetectorType::kSuperPoint;
    d.superpoint.weights = model.string();
  });
  std::printf("corridor with all four faults, SuperPoint: %.1f m, end error %.3f m (%.2f %%); %zu sweeps with the VIS "
              "factor, %zu refused for its tilt and bias; %zu resets by the LIS\n",
              r.path, r.end_error, 100 * r.end_error / r.path, r.stats.vis_factor_scans, r.acceleration_refusals,
              r.resets_by_the_lis);
  ASSERT_GT(r.path, 30.0);
  EXPECT_GT(r.acceleration_refusals, 0u) << "the re-initialised VIS must be seen tilted";
  EXPECT_GT(r.stats.vis_factor_scans, r.stats.scans_processed / 3) << "the VIS re-joined, untilted";
  // measured 1.00 %; with the check off (max_acceleration_difference 1e9) the same replay ends 22.2 m off (58 %)
  EXPECT_LT(r.end_error / r.path, 0.02);
}

}  // namespace
}  // namespace drover
