// KITTI devkit segment drift on constructed straight-line trajectories with closed-form answers.
#include <gtest/gtest.h>

#include <numbers>
#include <stdexcept>

#include "eval/kitti_drift.hpp"
#include "eval_fixtures.hpp"

namespace drover::eval {
namespace {

using test::pose;
using Poses = std::vector<Eigen::Isometry3d>;

// Ground truth: 351 frames 1 m apart along z (the KITTI camera's forward axis), 350 m in all. Path distances
// are whole metres (exact in double), so the devkit's last frame for start f and length L is f + L + 1 (the
// first frame strictly beyond L). Starts every 10 frames: L = 100 fits for f <= 249 (25 starts), L = 200 for
// f <= 149 (15), L = 300 for f <= 49 (5), longer lengths never: 45 segments.
constexpr int kFrames = 351;
Poses straightLine(double scale, double yaw_per_frame) {
  Poses p;
  for (int i = 0; i < kFrames; ++i)
    p.push_back(pose(Eigen::Vector3d(0, yaw_per_frame * i, 0), Eigen::Vector3d(0, 0, scale * i)));
  return p;
}

TEST(KittiDrift, DevkitHelpersUseStrictlyLongerSegments) {
  const std::vector<double> dist = trajectoryDistances(straightLine(1.0, 0.0));
  EXPECT_DOUBLE_EQ(dist[0], 0.0);
  EXPECT_DOUBLE_EQ(dist[350], 350.0);
  EXPECT_EQ(lastFrameFromSegmentLength(dist, 0, 100.0), 101);
  EXPECT_EQ(lastFrameFromSegmentLength(dist, 240, 100.0), 341);
  EXPECT_EQ(lastFrameFromSegmentLength(dist, 250, 100.0), -1);  // would need frame 351
}

TEST(KittiDrift, ConstantScaleErrorGivesAKnownTranslationDrift) {
  // Estimate 2 % too long: each segment's error is 0.02 (L + 1) m over L m, no rotation error.
  const double k = 0.02;
  const KittiDriftResult r = computeKittiDrift(straightLine(1.0, 0.0), straightLine(1.0 + k, 0.0));
  ASSERT_EQ(r.segments.size(), 45u);
  const double mean_ratio = (25 * 101.0 / 100.0 + 15 * 201.0 / 200.0 + 5 * 301.0 / 300.0) / 45.0;
  EXPECT_NEAR(r.t_err_percent, 100.0 * k * mean_ratio, 1e-10);
  EXPECT_NEAR(r.r_err_deg_per_100m, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.path_length, 350.0);
  ASSERT_EQ(r.per_length.size(), 8u);
  EXPECT_EQ(r.per_length[0].segments, 25u);
  EXPECT_NEAR(r.per_length[0].t_err_percent, 100.0 * k * 1.01, 1e-10);
  EXPECT_EQ(r.per_length[1].segments, 15u);
  EXPECT_NEAR(r.per_length[1].t_err_percent, 100.0 * k * 1.005, 1e-10);
  EXPECT_EQ(r.per_length[2].segments, 5u);
  EXPECT_NEAR(r.per_length[2].t_err_percent, 100.0 * k * 301.0 / 300.0, 1e-10);
  EXPECT_EQ(r.per_length[3].segments, 0u);
  EXPECT_EQ(r.per_length[7].length, 800.0);
}

TEST(KittiDrift, ConstantYawRateErrorGivesAKnownRotationDrift) {
  // The estimate turns w rad per frame where the ground truth does not: over a segment of L + 1 frames the
  // rotation error is w (L + 1) rad, i.e. w (L + 1) / L rad/m.
  const double w = 1e-4;
  const KittiDriftResult r = computeKittiDrift(straightLine(1.0, 0.0), straightLine(1.0, w));
  const double mean_ratio = (25 * 101.0 / 100.0 + 15 * 201.0 / 200.0 + 5 * 301.0 / 300.0) / 45.0;
  EXPECT_NEAR(r.r_err_deg_per_100m, w * mean_ratio * 180.0 / std::numbers::pi * 100.0, 1e-8);
  EXPECT_NEAR(r.per_length[0].r_err_deg_per_100m, w * 1.01 * 180.0 / std::numbers::pi * 100.0, 1e-8);
}

TEST(KittiDrift, PerfectEstimateHasZeroDrift) {
  const Poses gt = straightLine(1.0, 0.0);
  const KittiDriftResult r = computeKittiDrift(gt, gt);
  EXPECT_EQ(r.t_err_percent, 0.0);
  EXPECT_EQ(r.r_err_deg_per_100m, 0.0);
}

TEST(KittiDrift, RejectsUnequalCountsAndTrajectoriesShorterThanTheShortestSegment) {
  const Poses gt = straightLine(1.0, 0.0);
  Poses shorter = gt;
  shorter.pop_back();
  EXPECT_THROW(computeKittiDrift(gt, shorter), std::invalid_argument);
  const Poses stub(gt.begin(), gt.begin() + 100);  // 99 m: no 100 m segment
  try {
    computeKittiDrift(stub, stub);
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no segment"), std::string::npos) << e.what();
  }
  EXPECT_THROW(computeKittiDrift(Poses{}, Poses{}), std::invalid_argument);
  KittiDriftOptions bad;
  bad.step_size = 0;
  EXPECT_THROW(computeKittiDrift(gt, gt, bad), std::invalid_argument);
}

}  // namespace
}  // namespace drover::eval
