// The `odometry:` section of platform configs (io/odometry/odometry_config_io.hpp): every shipped file loads, keys
// reach the structs, and every kind of mistake is an IoError naming the file, line and dotted key. (In tests/cli
// because that is the test module linked with drover_io_odometry.)
#include <gtest/gtest.h>

#include <fstream>

#include "io/error.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

std::string config(const std::string& name) { return std::string(DROVER_SOURCE_DIR) + "/config/" + name; }

std::string writeYaml(const test::TempDir& dir, const std::string& text) {
  const std::string path = (dir / "c.yaml").string();
  std::ofstream(path) << text;
  return path;
}

std::string errorOf(const std::string& path) {
  try {
    loadOdometryConfig(path);
  } catch (const IoError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected IoError for " << path;
  return {};
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(OdometryConfigFile, EveryShippedConfigLoadsAndValidates) {
  for (const char* name : {"kitti.yaml", "kitti_raw.yaml", "m2dgr.yaml", "farm_sim.yaml", "euroc.yaml", "lvisam.yaml"})
    EXPECT_NO_THROW(loadOdometryConfig(config(name))) << name;
}

TEST(OdometryConfigFile, KittiConfigReadsRingsByOrderWithoutImuOrDeskew) {
  const pipeline::OdometryConfig c = loadOdometryConfig(config("kitti.yaml"));
  EXPECT_EQ(c.layout.ring_source, lidar::RingSource::kOrder);
  EXPECT_EQ(c.layout.n_rings, 64);
  EXPECT_TRUE(c.layout.order_top_down);
  EXPECT_FALSE(c.use_imu);
  EXPECT_FALSE(c.deskew);
  EXPECT_EQ(c.features.columns, 2083);
}

TEST(OdometryConfigFile, NestedKeysAndEnumerationsReachTheStructs) {
  test::TempDir dir;
  const pipeline::OdometryConfig c = loadOdometryConfig(writeYaml(
      dir, "odometry:\n  imu_wait: 0.5\n  layout:\n    spin: cw\n  matcher:\n    max_iterations: 7\n    kernel: huber\n"
           "  features:\n    edge_threshold: 2.5\n  smoother:\n    window: 4\n  imu:\n    gravity: 9.8\n"));
  EXPECT_DOUBLE_EQ(c.imu_wait, 0.5);
  EXPECT_EQ(c.layout.spin, lidar::SpinDirection::kClockwise);
  EXPECT_EQ(c.matcher.max_iterations, 7);
  EXPECT_EQ(c.matcher.kernel, lidar::RobustKernel::kHuber);
  EXPECT_FLOAT_EQ(c.features.edge_threshold, 2.5f);
  EXPECT_EQ(c.smoother.window, 4);
  // One gravity for the whole IMU chain.
  EXPECT_DOUBLE_EQ(c.propagator.gravity, 9.8);
  EXPECT_DOUBLE_EQ(c.initializer.gravity, 9.8);
}

TEST(OdometryConfigFile, UnknownKeysAreNamedWithTheirLineAndTheKnownKeys) {
  test::TempDir dir;
  const std::string top = errorOf(writeYaml(dir, "odometry:\n  use_imu: true\n  usee_imu: false\n"));
  EXPECT_TRUE(contains(top, "line 3") && contains(top, "odometry.usee_imu") && contains(top, "use_imu")) << top;
  const std::string nested = errorOf(writeYaml(dir, "odometry:\n  local_map:\n    radius: 10\n"));
  EXPECT_TRUE(contains(nested, "odometry.local_map.radius") && contains(nested, "surrounding_radius")) << nested;
}

TEST(OdometryConfigFile, WrongTypesAndBadEnumerationsAreErrors) {
  test::TempDir dir;
  EXPECT_TRUE(contains(errorOf(writeYaml(dir, "odometry:\n  min_points: many\n")), "odometry.min_points"));
  EXPECT_TRUE(contains(errorOf(writeYaml(dir, "odometry:\n  deskew: maybe\n")), "true or false"));
  EXPECT_TRUE(contains(errorOf(writeYaml(dir, "odometry:\n  layout:\n    ring_source: guess\n")), "elevation or order"));
  EXPECT_TRUE(contains(errorOf(writeYaml(dir, "odometry:\n  matcher:\n    kernel: cauchy\n")), "lio-sam or huber"));
  EXPECT_TRUE(contains(errorOf(writeYaml(dir, "odometry:\n  layout: [1, 2]\n")), "expected a map"));
}

TEST(OdometryConfigFile, ValuesThatFailValidationNameTheComponent) {
  test::TempDir dir;
  const std::string e = errorOf(writeYaml(dir, "odometry:\n  keyframes:\n    distance: -1\n"));
  EXPECT_TRUE(contains(e, "section 'odometry'") && contains(e, "keyframes")) << e;
}

TEST(OdometryConfigFile, MissingFileAndInvalidYamlAreNamed) {
  test::TempDir dir;
  EXPECT_TRUE(contains(errorOf((dir / "absent.yaml").string()), "not found"));
  const std::string e = errorOf(writeYaml(dir, "odometry:\n  use_imu: [true\n"));
  EXPECT_TRUE(contains(e, "invalid YAML")) << e;
}

}  // namespace
}  // namespace drover::io
