// The `sim:` section of a platform config (io/sim_dataset.hpp's SimConfigSettings): known keys read, unknown keys and
// bad values refused naming the file, line and key, and the shipped configs valid.
#include <gtest/gtest.h>

#include <string>

#include "io/config.hpp"
#include "io/sim_dataset.hpp"
#include "support/expect_io_error.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {
using test::expectIoError;
using test::TempDir;

TEST(SimConfigSettings, ReadsKnownKeysAndRejectsUnknownOnes) {
  TempDir tmp;
  test::writeText(tmp / "a.yaml", "dataset:\n  load_lidar: true\nsim:\n  lidar_model: hdl64\n  camera_rate_hz: 20\n"
                                  "  camera_color: true\n  camera_time_offset: -0.002\n  camera_pixel_samples: 2\n"
                                  "  camera_texture_filter: true\n  camera_edge_pixel_samples: 4\n");
  const SimConfigSettings s = loadSimConfigSettings((tmp / "a.yaml").string());
  EXPECT_EQ(s.lidar_model, "hdl64");
  EXPECT_EQ(s.camera_rate_hz, 20.0);
  EXPECT_EQ(s.camera_color, true);
  EXPECT_EQ(s.camera_time_offset_s, -0.002);
  EXPECT_EQ(s.camera_pixel_samples, 2);
  EXPECT_EQ(s.camera_texture_filter, true);
  EXPECT_EQ(s.camera_edge_pixel_samples, 4);
  EXPECT_FALSE(s.imu_rate_hz.has_value());
  test::writeText(tmp / "b.yaml", "sim:\n  lidar_modle: vlp32\n");
  expectIoError([&] { loadSimConfigSettings((tmp / "b.yaml").string()); }, {"b.yaml", "line 2", "sim.lidar_modle"});
  test::writeText(tmp / "c.yaml", "sim:\n  lidar_model: vlp17\n");
  expectIoError([&] { loadSimConfigSettings((tmp / "c.yaml").string()); }, {"c.yaml", "vlp17"});
  test::writeText(tmp / "d.yaml", "sim:\n  rig: drone\n");
  expectIoError([&] { loadSimConfigSettings((tmp / "d.yaml").string()); }, {"d.yaml", "sim.rig", "robot or euroc"});
}

TEST(SimConfigSettings, EurocConfigSimulatesOnEurocsRigAndTheFarmsOnTheRobots) {
  const std::string euroc = std::string(DROVER_SOURCE_DIR) + "/config/euroc.yaml";
  EXPECT_NO_THROW(loadDatasetOptions(euroc));
  EXPECT_EQ(loadSimConfigSettings(euroc).rig, "euroc");
  EXPECT_FALSE(loadSimConfigSettings(std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml").rig.has_value());
}

TEST(SimConfigSettings, RatesAndOffsetsShareTheOptionsRanges) {
  TempDir tmp;
  const auto error = [&](const std::string& text, std::initializer_list<std::string> fragments) {
    test::writeText(tmp / "s.yaml", "sim:\n  " + text + "\n");
    expectIoError([&] { loadSimConfigSettings((tmp / "s.yaml").string()); }, fragments);
  };
  error("imu_rate_hz: 1e9", {"s.yaml (line 2, key 'sim.imu_rate_hz')", "(0, 1000] Hz"});
  error("camera_rate_hz: 0", {"key 'sim.camera_rate_hz'", "(0, 60] Hz"});
  error("lidar_rate_hz: .nan", {"key 'sim.lidar_rate_hz'"});
  error("ground_truth_rate_hz: 50", {"[100, 1000] Hz"});
  error("lidar_time_offset: 2", {"key 'sim.lidar_time_offset'", "[-1, 1] s"});
  error("lidar_columns: 0", {"key 'sim.lidar_columns'", "[1, 100000]"});
  error("camera_pixel_samples: 5", {"key 'sim.camera_pixel_samples'", "[1, 4]"});
  error("camera_texture_filter: 2", {"key 'sim.camera_texture_filter'"});
  error("camera_edge_pixel_samples: 5", {"key 'sim.camera_edge_pixel_samples'", "[0, 4]"});
}

// Edge rays refine a pixel whose first rays disagree: a pixel needs several first rays, and fewer than the edge's.
TEST(SimConfigSettings, EdgePixelSamplesMustExceedThePixelSamples) {
  TempDir tmp;
  const auto load = [&](const std::string& text) {
    test::writeText(tmp / "e.yaml", "sim:\n" + text);
    return loadSimConfigSettings((tmp / "e.yaml").string());
  };
  EXPECT_EQ(load("  camera_pixel_samples: 2\n  camera_edge_pixel_samples: 3\n").camera_edge_pixel_samples, 3);
  EXPECT_EQ(load("  camera_edge_pixel_samples: 0\n").camera_edge_pixel_samples, 0);
  expectIoError([&] { load("  camera_pixel_samples: 2\n  camera_edge_pixel_samples: 2\n"); },
                {"e.yaml", "sim.camera_edge_pixel_samples", "more than sim.camera_pixel_samples (2)", "got 2"});
  expectIoError([&] { load("  camera_edge_pixel_samples: 4\n"); },
                {"sim.camera_edge_pixel_samples", "more than sim.camera_pixel_samples (1)", "at least 2", "got 4"});
}

TEST(SimConfigSettings, FarmSimConfigIsAValidPlatformAndSimConfig) {
  const std::string path = std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml";
  EXPECT_NO_THROW(loadDatasetOptions(path));
  const SimConfigSettings s = loadSimConfigSettings(path);
  EXPECT_EQ(s.lidar_model, "vlp16");
  EXPECT_EQ(s.camera_rate_hz, 15.0);
}

}  // namespace
}  // namespace drover::io
