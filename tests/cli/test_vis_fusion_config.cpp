// The `odometry.vis_fusion` section (how the VIS's motion enters the LIS): every key reaches its own field, and a
// bad value or an unknown key is an IoError naming the file, the line or section and the key.
#include <gtest/gtest.h>

#include <string>

#include "io/odometry/odometry_config_io.hpp"
#include "odometry_config_test_util.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

using test_config::errorOf;
using test_config::has;
using test_config::load;

TEST(VisFusionConfigReader, EveryKeyReachesItsOwnField) {
  test::TempDir dir;
  const pipeline::VisualMotionConfig c =
      load(dir,
           "odometry:\n  vis_fusion:\n    factor: false\n    factor_degenerate_only: true\n    initial_guess: false\n"
           "    initial_guess_degenerate_only: false\n"
           "    sigma_position: 0.03\n"
           "    sigma_position_ratio: 0.06\n    sigma_rotation: 0.02\n    sigma_rotation_ratio: 0.07\n"
           "    min_features: 25\n    full_features: 90\n    warmup: 1.5\n    max_age: 0.25\n"
           "    max_keyframe_gap: 0.6\n    standing_speed: 0.3\n    keyframe_gap_min_distance: 0.35\n"
           "    keyframe_gap_velocity_tolerance: 0.15\n"
           "    max_velocity_difference: 1.1\n    max_velocity_difference_ratio: 0.07\n"
           "    max_velocity_difference_growth: 0.04\n"
           "    max_acceleration_difference: 0.09\n"
           "    max_position_difference: 0.45\n    reset_after: 2.5\n    window_covariance: true\n"
           "    window_floor_position: 0.007\n    window_floor_rotation: 0.003\n")
          .vis_fusion;
  EXPECT_FALSE(c.factor);
  EXPECT_TRUE(c.factor_degenerate_only);
  EXPECT_FALSE(c.initial_guess);
  EXPECT_FALSE(c.initial_guess_degenerate_only);
  EXPECT_DOUBLE_EQ(c.sigma_position, 0.03);
  EXPECT_DOUBLE_EQ(c.sigma_position_ratio, 0.06);
  EXPECT_DOUBLE_EQ(c.sigma_rotation, 0.02);
  EXPECT_DOUBLE_EQ(c.sigma_rotation_ratio, 0.07);
  EXPECT_EQ(c.min_features, 25);
  EXPECT_EQ(c.full_features, 90);
  EXPECT_DOUBLE_EQ(c.warmup, 1.5);
  EXPECT_DOUBLE_EQ(c.max_age, 0.25);
  EXPECT_DOUBLE_EQ(c.max_keyframe_gap, 0.6);
  EXPECT_DOUBLE_EQ(c.standing_speed, 0.3);
  EXPECT_DOUBLE_EQ(c.keyframe_gap_min_distance, 0.35);
  EXPECT_DOUBLE_EQ(c.keyframe_gap_velocity_tolerance, 0.15);
  EXPECT_DOUBLE_EQ(c.max_velocity_difference, 1.1);
  EXPECT_DOUBLE_EQ(c.max_velocity_difference_ratio, 0.07);
  EXPECT_DOUBLE_EQ(c.max_velocity_difference_growth, 0.04);
  EXPECT_DOUBLE_EQ(c.max_acceleration_difference, 0.09);
  EXPECT_DOUBLE_EQ(c.max_position_difference, 0.45);
  EXPECT_DOUBLE_EQ(c.reset_after, 2.5);
  EXPECT_TRUE(c.window_covariance);
  EXPECT_DOUBLE_EQ(c.window_floor_position, 0.007);
  EXPECT_DOUBLE_EQ(c.window_floor_rotation, 0.003);
}

// The switches the presets and the ablation turn: odometry.degenerate_pose_from_match and loop.visual_yaw_prior.
TEST(VisFusionConfigReader, ThePresetsSwitchesReachTheirFieldsAndRejectNonBooleans) {
  test::TempDir dir;
  const pipeline::OdometryConfig c =
      load(dir, "odometry:\n  degenerate_pose_from_match: true\nloop:\n  visual_yaw_prior: false\n");
  EXPECT_TRUE(c.degenerate_pose_from_match);
  EXPECT_FALSE(c.loop.visual_yaw_prior);
  const pipeline::OdometryConfig d = load(dir, "odometry:\n  use_imu: true\n");
  EXPECT_FALSE(d.degenerate_pose_from_match) << "Drover's own default: the smoother's pose";
  EXPECT_TRUE(d.loop.visual_yaw_prior);
  const std::string file = (dir / "odometry.yaml").string();
  const std::string match = errorOf(dir, "odometry:\n  degenerate_pose_from_match: sometimes\n");
  EXPECT_TRUE(has(match, file) && has(match, "degenerate_pose_from_match")) << match;
  const std::string prior = errorOf(dir, "loop:\n  visual_yaw_prior: 2\n");
  EXPECT_TRUE(has(prior, file) && has(prior, "visual_yaw_prior")) << prior;
}

TEST(VisFusionConfigReader, BadValuesAndUnknownKeysAreErrorsNamingFileAndKey) {
  test::TempDir dir;
  const std::string file = (dir / "odometry.yaml").string();
  const std::string negative = errorOf(dir, "odometry:\n  vis_fusion:\n    max_age: -1\n");
  EXPECT_TRUE(has(negative, file) && has(negative, "max_age")) << negative;
  const std::string order = errorOf(dir, "odometry:\n  vis_fusion:\n    min_features: 100\n");
  EXPECT_TRUE(has(order, file) && has(order, "section 'odometry'") && has(order, "min_features")) << order;
  const std::string zero = errorOf(dir, "odometry:\n  vis_fusion:\n    max_position_difference: 0\n");
  EXPECT_TRUE(has(zero, file) && has(zero, "max_position_difference")) << zero;
  const std::string accel = errorOf(dir, "odometry:\n  vis_fusion:\n    max_acceleration_difference: 0\n");
  EXPECT_TRUE(has(accel, file) && has(accel, "max_acceleration_difference")) << accel;
  const std::string floor = errorOf(dir, "odometry:\n  vis_fusion:\n    window_floor_rotation: 0\n");
  EXPECT_TRUE(has(floor, file) && has(floor, "window_floor_rotation")) << floor;
  const std::string travel = errorOf(dir, "odometry:\n  vis_fusion:\n    keyframe_gap_min_distance: -0.1\n");
  EXPECT_TRUE(has(travel, file) && has(travel, "keyframe_gap_min_distance")) << travel;
  const std::string travel_text = errorOf(dir, "odometry:\n  vis_fusion:\n    keyframe_gap_min_distance: far\n");
  EXPECT_TRUE(has(travel_text, file) && has(travel_text, "keyframe_gap_min_distance")) << travel_text;
  const std::string tolerance = errorOf(dir, "odometry:\n  vis_fusion:\n    keyframe_gap_velocity_tolerance: -0.2\n");
  EXPECT_TRUE(has(tolerance, file) && has(tolerance, "keyframe_gap_velocity_tolerance")) << tolerance;
  const std::string ratio = errorOf(dir, "odometry:\n  vis_fusion:\n    max_velocity_difference_ratio: -0.05\n");
  EXPECT_TRUE(has(ratio, file) && has(ratio, "max_velocity_difference_ratio")) << ratio;
  const std::string growth = errorOf(dir, "odometry:\n  vis_fusion:\n    max_velocity_difference_growth: fast\n");
  EXPECT_TRUE(has(growth, file) && has(growth, "max_velocity_difference_growth")) << growth;
  const std::string flag = errorOf(dir, "odometry:\n  vis_fusion:\n    window_covariance: maybe\n");
  EXPECT_TRUE(has(flag, file) && has(flag, "window_covariance")) << flag;
  const std::string unknown = errorOf(dir, "odometry:\n  vis_fusion:\n    facter: true\n");
  EXPECT_TRUE(has(unknown, "line 3") && has(unknown, "'odometry.vis_fusion.facter'")) << unknown;
}

}  // namespace
}  // namespace drover::io
