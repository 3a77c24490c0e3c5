// The VIS's attitude history as loop closure's shift prior (pipeline::VisualYawHistory): the lidars' relative yaw
// from two VIS states through the lidar's mount, and no prior across a VIS reset or far from any state.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "pipeline/visual_yaw_history.hpp"
#include "support/units.hpp"

namespace drover::pipeline {
namespace {

using ::drover::test::kMs;

VisualState stateAt(Time t, double yaw, double pitch, std::uint32_t reset_id) {
  VisualState s;
  s.t = t;
  s.T_world_imu.linear() =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  s.reset_id = reset_id;
  return s;
}

TEST(VisualYawHistory, TheRelativeYawOfTheLidarsComesThroughTheMountAndSignMatchesPCandidateEqualsRzPQuery) {
  // A lidar mounted upside down about x (its z down): the IMU's +0.5 rad turn is the lidar's -0.5 rad.
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();
  T_imu_lidar.linear() = Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T_imu_lidar.translation() = Eigen::Vector3d(0.1, 0.0, 0.3);
  VisualYawHistory h(T_imu_lidar);
  h.add(stateAt(1000 * kMs, 0.2, 0.01, 3));
  h.add(stateAt(40000 * kMs, 0.7, -0.02, 3));
  ASSERT_TRUE(h.yaw(1000 * kMs, 40000 * kMs).has_value());
  EXPECT_NEAR(*h.yaw(1000 * kMs, 40000 * kMs), -0.5, 2e-3);  // small pitches change yaw by < 1e-3
  Eigen::Isometry3d upright = Eigen::Isometry3d::Identity();
  VisualYawHistory u(upright);
  u.add(stateAt(1000 * kMs, 0.2, 0.0, 3));
  u.add(stateAt(40000 * kMs, 0.7, 0.0, 3));
  EXPECT_NEAR(*u.yaw(1000 * kMs, 40000 * kMs), 0.5, 1e-12);
  EXPECT_NEAR(*u.prior()(40000 * kMs, 1000 * kMs), -0.5, 1e-12);
}

TEST(VisualYawHistory, NoPriorAcrossAResetOrFartherThanTheGapFromAnyStateAndStatesAreThinnedToTheSpacing) {
  VisualYawHistory h(Eigen::Isometry3d::Identity(), 0.1, 0.15);
  for (int k = 0; k < 100; ++k) h.add(stateAt(k * 1000 * kMs / 15, 0.01 * k, 0.0, 1));  // 15 Hz, 6.6 s
  h.add(stateAt(7000 * kMs, 1.0, 0.0, 2));  // a reset: kept although 67 ms after the previous state
  EXPECT_LE(h.size(), 52u);                 // ~10 per second
  EXPECT_GE(h.size(), 48u);
  EXPECT_TRUE(h.yaw(0, 6000 * kMs).has_value());
  EXPECT_FALSE(h.yaw(0, 7000 * kMs).has_value()) << "different reset IDs";
  EXPECT_FALSE(h.yaw(0, 7300 * kMs).has_value()) << "0.3 s from the newest state";
  EXPECT_FALSE(h.yaw(-500 * kMs, 6000 * kMs).has_value()) << "before the first state";
  h.add(stateAt(6900 * kMs, 0.0, 0.0, 2));  // out of order: ignored
  EXPECT_NEAR(*h.yaw(7000 * kMs, 7000 * kMs), 0.0, 1e-12);
}

}  // namespace
}  // namespace drover::pipeline
