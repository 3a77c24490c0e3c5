// The `vio:` section of a platform config: every key reaches VioConfig, an unknown key or a bad value is an error
// naming the file, the line and the key, and the shipped configs load. (In tests/cli because that test module links
// drover_io_visual.)
#include <gtest/gtest.h>

#include <string>

#include "io/error.hpp"
#include "io/visual/vio_config_io.hpp"
#include "support/expect_io_error.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {

TEST(VioConfigIo, KeysReachTheConfigWithTheirUnits) {
  TempDir dir;
  const vio::VioConfig c = io::loadVioConfig(writePlatformFile(dir, R"(vio:
  window: 7
  min_parallax_px: 12.5
  max_keyframe_interval_s: 0.75
  sigma_px: 2.0
  depth_mode: factor
  depth_sigma_m: 0.1
  max_solver_ms: 25
  estimate_time_offset: true
  time_offset_sigma_s: 0.002
  init: visual
  init_min_acc_excitation: 0.1
  init_max_scale_rel_sigma: 0.05
  scale_check_span_s: 20
  scale_check_max_change: 1.5
  coast_max_s: 12
  scale_check_bias_sigma: 0.05
  lis_sigma_rotation_rad: 0.02
  seed_max_median_px: 4.5
  seed_min_observations: 40
  max_imu_gap_s: 0.2
  imu_midpoint: false
  lis_bias_prior_sigma_gyro: 0.001
  lis_bias_prior_sigma_acc: 0.02
  acc_bias_prior_sigma: 0.08
  ground_height_m: 0.65
  ground_sigma_m: 0.05
  ground_slope_sigma_rad: 0.03
  ground_gate_rel: 0.3
  ground_max_range_m: 6
  ground_check_every_s: 2
  ground_check_min_points: 30
  ground_check_cluster_rel: 0.05
)"));
  EXPECT_EQ(c.window, 7);
  EXPECT_DOUBLE_EQ(c.min_parallax_px, 12.5);
  EXPECT_DOUBLE_EQ(c.max_keyframe_interval_s, 0.75);
  EXPECT_DOUBLE_EQ(c.sigma_px, 2.0);
  EXPECT_EQ(c.depth_mode, vio::DepthMode::kFactor);
  EXPECT_DOUBLE_EQ(c.depth_sigma_m, 0.1);
  EXPECT_DOUBLE_EQ(c.max_solver_ms, 25);
  EXPECT_TRUE(c.estimate_time_offset);
  EXPECT_DOUBLE_EQ(c.time_offset_sigma_s, 0.002);
  EXPECT_EQ(c.init, vio::InitMode::kVisual);
  EXPECT_DOUBLE_EQ(c.init_min_acc_excitation, 0.1);
  EXPECT_DOUBLE_EQ(c.init_max_scale_rel_sigma, 0.05);
  EXPECT_DOUBLE_EQ(c.scale_check_span_s, 20);
  EXPECT_DOUBLE_EQ(c.scale_check_max_change, 1.5);
  EXPECT_DOUBLE_EQ(c.coast_max_s, 12);
  EXPECT_DOUBLE_EQ(c.scale_check_bias_sigma, 0.05);
  EXPECT_DOUBLE_EQ(c.lis_sigma_rotation_rad, 0.02);
  EXPECT_DOUBLE_EQ(c.seed_max_median_px, 4.5);
  EXPECT_EQ(c.seed_min_observations, 40);
  EXPECT_DOUBLE_EQ(c.max_imu_gap_s, 0.2);
  EXPECT_FALSE(c.imu_midpoint);
  EXPECT_DOUBLE_EQ(c.lis_bias_prior_sigma_gyro, 0.001);
  EXPECT_DOUBLE_EQ(c.lis_bias_prior_sigma_acc, 0.02);
  EXPECT_DOUBLE_EQ(c.acc_bias_prior_sigma, 0.08);
  EXPECT_DOUBLE_EQ(c.ground_height_m, 0.65);
  EXPECT_DOUBLE_EQ(c.ground_sigma_m, 0.05);
  EXPECT_DOUBLE_EQ(c.ground_slope_sigma_rad, 0.03);
  EXPECT_DOUBLE_EQ(c.ground_gate_rel, 0.3);
  EXPECT_DOUBLE_EQ(c.ground_max_range_m, 6);
  EXPECT_DOUBLE_EQ(c.ground_check_every_s, 2);
  EXPECT_EQ(c.ground_check_min_points, 30);
  EXPECT_DOUBLE_EQ(c.ground_check_cluster_rel, 0.05);
}

TEST(VioConfigIo, AFileWithoutTheSectionGivesTheDefaults) {
  TempDir dir;
  const vio::VioConfig c = io::loadVioConfig(writePlatformFile(dir, "odometry:\n  use_imu: true\n"));
  EXPECT_EQ(c.window, vio::VioConfig{}.window);
  EXPECT_EQ(c.depth_mode, vio::DepthMode::kFixed);
}

TEST(VioConfigIo, ANegativeSeedThresholdOrNoObservationsIsAnErrorNamingTheValue) {
  TempDir dir;
  for (const auto& [yaml, words] : std::vector<std::pair<std::string, std::string>>{
           {"vio:\n  seed_max_median_px: -1\n", "seed_max_median_px must be >= 0"},
           {"vio:\n  seed_min_observations: 0\n", "seed_min_observations must be >= 1"},
           {"vio:\n  lis_bias_prior_sigma_acc: 0.02\n", "both 0 (off) or both > 0"},
           {"vio:\n  lis_bias_prior_sigma_gyro: -1\n  lis_bias_prior_sigma_acc: 0.02\n", "must be >= 0"}}) {
    SCOPED_TRACE(yaml);
    const std::string path = writePlatformFile(dir, yaml);
    test::expectIoError([&] { io::loadVioConfig(path); }, {"platform.yaml", words});
  }
}

TEST(VioConfigIo, AnUnknownKeyABadChoiceOrAnInvalidValueNamesTheFileLineAndKey) {
  TempDir dir;
  for (const auto& [yaml, words] : std::vector<std::pair<std::string, std::string>>{
           {"vio:\n  windw: 10\n", "vio.windw"},
           {"vio:\n  depth_mode: sometimes\n", "vio.depth_mode"},
           {"vio:\n  window: 2\n", "window must be in [3, 50]"},
           {"vio:\n  sigma_px: -1\n", "sigma_px must be > 0"},
           {"vio:\n  max_time_offset_s: nan\n", "vio.max_time_offset_s"},
           {"vio:\n  relative_covariance: often\n", "vio.relative_covariance"},
           {"vio:\n  init_max_scale_rel_sigma: 0\n", "init_max_scale_rel_sigma must be > 0"},
           {"vio:\n  scale_check_span_s: -5\n", "scale_check_span_s must be >= 0"},
           {"vio:\n  scale_check_max_change: 1\n", "scale_check_max_change must be > 1"},
           {"vio:\n  coast_max_s: -1\n", "coast_max_s must be >= 0"},
           {"vio:\n  max_keyframe_interval_s: -0.5\n", "max_keyframe_interval_s must be >= 0"},
           {"vio:\n  scale_check_bias_sigma: -0.1\n", "scale_check_bias_sigma must be >= 0"},
           {"vio:\n  acc_bias_prior_sigma: -0.05\n", "acc_bias_prior_sigma must be >= 0"},
           {"vio:\n  ground_height_m: -0.4\n", "ground_height_m must be >= 0"},
           {"vio:\n  ground_sigma_m: 0\n", "ground_sigma_m must be > 0"},
           {"vio:\n  ground_gate_rel: 1.5\n", "ground_gate_rel must be in (0, 1)"},
           {"vio:\n  ground_check_every_s: -1\n", "ground_check_every_s must be >= 0"},
           {"vio:\n  ground_check_min_points: 2\n", "ground_check_min_points >= 3"},
           {"vio:\n  ground_check_cluster_rel: 0.5\n", "ground_check_cluster_rel in (0, 0.5)"}}) {
    SCOPED_TRACE(yaml);
    const std::string path = writePlatformFile(dir, yaml);
    test::expectIoError([&] { io::loadVioConfig(path); }, {"platform.yaml", "line", words});
  }
}

TEST(VioConfigIo, TheShippedConfigsLoad) {
  for (const char* name : {"farm_sim.yaml", "car_sim.yaml", "euroc.yaml"}) {
    const vio::VioConfig c = io::loadVioConfig(std::string(DROVER_SOURCE_DIR) + "/config/" + name);
    EXPECT_EQ(c.validate(), "") << name;
  }
}

}  // namespace
}  // namespace drover::test
