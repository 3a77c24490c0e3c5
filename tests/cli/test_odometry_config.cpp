// The `odometry:` section of a platform config -> pipeline::OdometryConfig (io/odometry/odometry_config_io.hpp):
// the shipped configs load, every key reaches its own field (distinct values per key catch a key bound to the
// wrong field); bad input is in test_odometry_config_errors.cpp. (In tests/cli because that test module links
// drover_io_odometry.)
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <string>

#include "io/odometry/odometry_config_io.hpp"
#include "odometry_config_test_util.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

using pipeline::OdometryConfig;

using test_config::load;
using test_config::shipped;

TEST(OdometryConfigReader, EveryShippedConfigLoadsAndPassesValidation) {
  for (const char* name :
       {"kitti.yaml", "kitti_raw.yaml", "m2dgr.yaml", "farm_sim.yaml", "farm_sim_bag.yaml", "car_sim.yaml", "euroc.yaml",
        "lvisam.yaml"}) {
    SCOPED_TRACE(name);
    OdometryConfig c;
    ASSERT_NO_THROW(c = loadOdometryConfig(shipped(name)));
    EXPECT_EQ(c.validate(), "");
  }
}

TEST(OdometryConfigReader, KittiConfigTakesRingsFromPointOrderWith64RingsAndNeitherImuNorDeskew) {
  const OdometryConfig c = loadOdometryConfig(shipped("kitti.yaml"));
  EXPECT_EQ(c.layout.ring_source, lidar::RingSource::kOrder);
  EXPECT_EQ(c.layout.n_rings, 64);
  EXPECT_FALSE(c.use_imu);
  EXPECT_FALSE(c.deskew);
  EXPECT_DOUBLE_EQ(c.layout.min_range, 3.0);
  EXPECT_DOUBLE_EQ(c.local_map.surrounding_radius, 50.0);
}

TEST(OdometryConfigReader, FarmSimConfigGivesTheSimulatorsImuNoiseToTheWholeImuChain) {
  const OdometryConfig c = loadOdometryConfig(shipped("farm_sim.yaml"));
  EXPECT_TRUE(c.use_imu);
  EXPECT_TRUE(c.deskew);
  EXPECT_EQ(c.layout.n_rings, 16);
  EXPECT_EQ(c.smoother.window, 5);
  EXPECT_DOUBLE_EQ(c.preintegration.gyro_noise_density, 1.7e-4);
  EXPECT_DOUBLE_EQ(c.preintegration.acc_bias_random_walk, 3.0e-4);
  EXPECT_DOUBLE_EQ(c.propagator.gravity, 9.81);
  EXPECT_DOUBLE_EQ(c.initializer.gravity, 9.81);
}

// The simulated car is the farm's platform with LIO-SAM's outdoor map leaf and the car's ground height: the same
// sensors (a course rendered with either file is the same data) and, but for the leaf and the loop graph's rotation
// sigma (the car's heading drifts 1e-4 rad a keyframe, the farm robot's 1e-3), the same LIS and loops.
TEST(OdometryConfigReader, CarSimIsTheFarmsPlatformWithTheOutdoorPlaneLeafTheCarsGroundHeightAndItsHeadingDrift) {
  const YAML::Node farm = YAML::LoadFile(shipped("farm_sim.yaml"));
  const YAML::Node car = YAML::LoadFile(shipped("car_sim.yaml"));
  for (const char* section : {"dataset", "sim", "visual"}) {
    EXPECT_EQ(YAML::Dump(car[section]), YAML::Dump(farm[section])) << section;
  }
  YAML::Node car_odometry = YAML::Clone(car["odometry"]);
  EXPECT_DOUBLE_EQ(car_odometry["local_map"]["plane_leaf"].as<double>(), 0.4);
  EXPECT_DOUBLE_EQ(farm["odometry"]["local_map"]["plane_leaf"].as<double>(), 0.2);
  car_odometry["local_map"]["plane_leaf"] = farm["odometry"]["local_map"]["plane_leaf"];
  EXPECT_EQ(YAML::Dump(car_odometry), YAML::Dump(farm["odometry"]));
  EXPECT_DOUBLE_EQ(car["vio"]["ground_height_m"].as<double>(), 1.65);
  EXPECT_DOUBLE_EQ(farm["vio"]["ground_height_m"].as<double>(), 0.4);
  YAML::Node car_vio = YAML::Clone(car["vio"]);
  car_vio["ground_height_m"] = farm["vio"]["ground_height_m"];
  EXPECT_EQ(YAML::Dump(car_vio), YAML::Dump(farm["vio"]));
  YAML::Node car_loop = YAML::Clone(car["loop"]);
  EXPECT_FALSE(farm["loop"]["odometry_sigma_rotation"]) << "the farm keeps the default";
  car_loop.remove("odometry_sigma_rotation");
  EXPECT_EQ(YAML::Dump(car_loop), YAML::Dump(farm["loop"]));
  const OdometryConfig car_config = loadOdometryConfig(shipped("car_sim.yaml"));
  EXPECT_DOUBLE_EQ(car_config.local_map.plane_leaf, 0.4);
  EXPECT_DOUBLE_EQ(car_config.loop.odometry_sigma_rotation, 0.0002);
  EXPECT_DOUBLE_EQ(loadOdometryConfig(shipped("farm_sim.yaml")).loop.odometry_sigma_rotation,
                   pipeline::LoopClosureConfig{}.odometry_sigma_rotation);
}

// euroc.yaml and lvisam.yaml describe their sensors (the IMU's noise, the lidar's rings) and nothing of the method.
TEST(OdometryConfigReader, ConfigsThatDescribeOnlyTheirSensorsLeaveTheMethodAtTheDefaults) {
  const OdometryConfig d;
  for (const char* name : {"euroc.yaml", "lvisam.yaml"}) {
    SCOPED_TRACE(name);
    const OdometryConfig c = loadOdometryConfig(shipped(name));
    EXPECT_EQ(c.use_imu, d.use_imu);
    EXPECT_EQ(c.layout.n_rings, d.layout.n_rings);
    EXPECT_EQ(c.layout.spin, d.layout.spin);
    EXPECT_EQ(c.layout.ring_source, d.layout.ring_source);
    EXPECT_EQ(c.matcher.kernel, d.matcher.kernel);
    EXPECT_EQ(c.matcher.max_iterations, d.matcher.max_iterations);
    EXPECT_EQ(c.features.edge_threshold, d.features.edge_threshold);
    EXPECT_EQ(c.keyframes.distance, d.keyframes.distance);
    EXPECT_EQ(c.smoother.window, d.smoother.window);
  }
}

TEST(OdometryConfigReader, AnEmptyFileAndAnEmptySectionGiveTheDefaults) {
  test::TempDir dir;
  const OdometryConfig d;
  for (const char* text : {"", "odometry:\n", "dataset:\n  load_imu: true\n"}) {
    const OdometryConfig c = load(dir, text);
    EXPECT_EQ(c.layout.ring_source, d.layout.ring_source) << text;
    EXPECT_EQ(c.matcher.max_iterations, d.matcher.max_iterations) << text;
  }
}

TEST(OdometryConfigReader, NestedKeysReachTheStructAndLeaveTheOthersAtTheirDefaults) {
  test::TempDir dir;
  const OdometryConfig c = load(dir,
                                "odometry:\n"
                                "  matcher:\n    max_iterations: 7\n    kernel: huber\n"
                                "  layout:\n    spin: cw\n"
                                "  features:\n    edge_threshold: 0.35\n");
  const OdometryConfig d;
  EXPECT_EQ(c.matcher.max_iterations, 7);
  EXPECT_EQ(c.matcher.kernel, lidar::RobustKernel::kHuber);
  EXPECT_EQ(c.layout.spin, lidar::SpinDirection::kClockwise);
  EXPECT_EQ(c.features.edge_threshold, 0.35f);  // the float nearest 0.35, exactly
  EXPECT_EQ(c.matcher.huber_delta, d.matcher.huber_delta);
  EXPECT_EQ(c.layout.ring_source, d.layout.ring_source);
  EXPECT_EQ(c.layout.n_rings, d.layout.n_rings);
  EXPECT_EQ(c.features.surf_threshold, d.features.surf_threshold);
}

TEST(OdometryConfigReader, EveryTopLevelKeyReachesItsOwnField) {
  test::TempDir dir;
  const OdometryConfig c = load(dir,
                                "odometry:\n  use_imu: false\n  deskew: false\n  min_points: 50\n  imu_wait: 0.2\n"
                                "  lidar_sigma_position: 0.04\n  lidar_sigma_rotation: 0.03\n  degenerate_sigma: 5\n"
                                "  lidar_sigma_rotation_unaided: 0.06\n"
                                "  gravity_roll_pitch: false\n  deskew_refinements: 2\n"
                                "  degenerate_restart_sweeps: 11\n  use_imu_orientation: false\n"
                                "  moving_start_restart: 5\n  moving_start_speed: 0.4\n"
                                "  static_start_sigma_velocity: 0.02\n");
  EXPECT_FALSE(c.use_imu);
  EXPECT_FALSE(c.deskew);
  EXPECT_EQ(c.min_points, 50);
  EXPECT_DOUBLE_EQ(c.imu_wait, 0.2);
  EXPECT_DOUBLE_EQ(c.lidar_sigma_position, 0.04);
  EXPECT_DOUBLE_EQ(c.lidar_sigma_rotation, 0.03);
  EXPECT_DOUBLE_EQ(c.degenerate_sigma, 5.0);
  EXPECT_DOUBLE_EQ(c.lidar_sigma_rotation_unaided, 0.06);
  EXPECT_EQ(OdometryConfig{}.lidar_sigma_rotation_unaided, 0.0) << "the same as lidar_sigma_rotation by default";
  OdometryConfig negative;
  negative.lidar_sigma_rotation_unaided = -0.01;
  EXPECT_NE(negative.validate().find("lidar_sigma_rotation_unaided"), std::string::npos);
  EXPECT_FALSE(c.gravity_roll_pitch);
  EXPECT_EQ(c.deskew_refinements, 2);
  EXPECT_EQ(c.degenerate_restart_sweeps, 11);
  EXPECT_EQ(c.moving_start_restart, 5);
  EXPECT_DOUBLE_EQ(c.moving_start_speed, 0.4);
  EXPECT_DOUBLE_EQ(c.static_start_sigma_velocity, 0.02);
  EXPECT_EQ(OdometryConfig{}.static_start_sigma_velocity, 0.0) << "off by default";
  EXPECT_FALSE(c.initializer.use_orientation);
  EXPECT_TRUE(OdometryConfig{}.initializer.use_orientation) << "a 9-axis unit's orientation is used by default";
}

TEST(OdometryConfigReader, EveryLayoutAndFeatureKeyReachesItsOwnField) {
  test::TempDir dir;
  const OdometryConfig c = load(
      dir,
      "odometry:\n  layout:\n    n_rings: 32\n    vertical_fov_min_deg: -20.5\n    vertical_fov_max_deg: 10.5\n"
      "    columns: 1024\n    scan_period: 0.05\n    spin: cw\n    ring_source: order\n    order_top_down: true\n"
      "    seam_tolerance_deg: 0.2\n    min_range: 0.7\n    max_range: 80\n"
      "  features:\n    columns: 1000\n    min_range: 0.6\n    max_range: 90\n    half_window: 4\n"
      "    edge_threshold: 0.9\n    surf_threshold: 0.05\n    sub_regions: 8\n    max_edges_per_region: 15\n"
      "    suppression_radius: 3\n    max_column_gap: 7\n    occlusion_depth_gap: 0.25\n    parallel_ratio: 0.03\n"
      "    edge_leaf: 0.1\n    surf_leaf: 0.3\n    full_leaf: 0.35\n");
  const lidar::ScanLayoutConfig& l = c.layout;
  EXPECT_EQ(l.n_rings, 32);
  EXPECT_DOUBLE_EQ(l.vertical_fov_min_deg, -20.5);
  EXPECT_DOUBLE_EQ(l.vertical_fov_max_deg, 10.5);
  EXPECT_EQ(l.columns, 1024);
  EXPECT_DOUBLE_EQ(l.scan_period, 0.05);
  EXPECT_EQ(l.spin, lidar::SpinDirection::kClockwise);
  EXPECT_EQ(l.ring_source, lidar::RingSource::kOrder);
  EXPECT_TRUE(l.order_top_down);
  EXPECT_DOUBLE_EQ(l.seam_tolerance_deg, 0.2);
  EXPECT_DOUBLE_EQ(l.min_range, 0.7);
  EXPECT_DOUBLE_EQ(l.max_range, 80.0);
  const lidar::FeatureExtractorConfig& f = c.features;
  EXPECT_EQ(f.columns, 1000);
  EXPECT_DOUBLE_EQ(f.min_range, 0.6);
  EXPECT_DOUBLE_EQ(f.max_range, 90.0);
  EXPECT_EQ(f.half_window, 4);
  EXPECT_EQ(f.edge_threshold, 0.9f);
  EXPECT_EQ(f.surf_threshold, 0.05f);
  EXPECT_EQ(f.sub_regions, 8);
  EXPECT_EQ(f.max_edges_per_region, 15);
  EXPECT_EQ(f.suppression_radius, 3);
  EXPECT_EQ(f.max_column_gap, 7);
  EXPECT_EQ(f.occlusion_depth_gap, 0.25f);
  EXPECT_EQ(f.parallel_ratio, 0.03f);
  EXPECT_EQ(f.edge_leaf, 0.1f);
  EXPECT_EQ(f.surf_leaf, 0.3f);
  EXPECT_EQ(f.full_leaf, 0.35f);
}

TEST(OdometryConfigReader, EveryLocalMapMatcherAndKeyframeKeyReachesItsOwnField) {
  test::TempDir dir;
  const OdometryConfig c = load(
      dir,
      "odometry:\n  local_map:\n    surrounding_radius: 40\n    keyframe_density: 1.5\n    recent_window: 5\n"
      "    recent_count: 3\n    edge_leaf: 0.15\n    plane_leaf: 0.35\n    full_leaf: 0.05\n    cache_capacity: 500\n"
      "    retire_radius: 0.7\n    retire_age: 45\n"
      "  matcher:\n    max_iterations: 12\n    convergence_translation: 0.001\n    convergence_rotation: 0.002\n"
      "    neighbors: 6\n    max_neighbor_distance: 1.5\n    edge_eigen_ratio: 4\n    plane_tolerance: 0.15\n"
      "    plane_min_aspect: 0.05\n"
      "    kernel: huber\n    min_weight: 0.2\n    huber_delta: 0.05\n    degeneracy_threshold: 50\n"
      "    degeneracy_threshold_per_correspondence: 0.03\n"
      "    min_edge_features: 5\n    min_plane_features: 60\n    min_correspondences: 40\n"
      "  keyframes:\n    distance: 0.5\n    angle: 0.1\n");
  const lidar::LocalMapConfig& m = c.local_map;
  EXPECT_DOUBLE_EQ(m.surrounding_radius, 40.0);
  EXPECT_DOUBLE_EQ(m.keyframe_density, 1.5);
  EXPECT_DOUBLE_EQ(m.recent_window, 5.0);
  EXPECT_EQ(m.recent_count, 3);
  EXPECT_DOUBLE_EQ(m.edge_leaf, 0.15);
  EXPECT_DOUBLE_EQ(m.plane_leaf, 0.35);
  EXPECT_DOUBLE_EQ(m.full_leaf, 0.05);
  EXPECT_EQ(m.cache_capacity, 500);
  EXPECT_DOUBLE_EQ(m.retire_radius, 0.7);
  EXPECT_DOUBLE_EQ(m.retire_age, 45.0);
  const lidar::ScanMatcherConfig& s = c.matcher;
  EXPECT_EQ(s.max_iterations, 12);
  EXPECT_DOUBLE_EQ(s.convergence_translation, 0.001);
  EXPECT_DOUBLE_EQ(s.convergence_rotation, 0.002);
  EXPECT_EQ(s.neighbors, 6);
  EXPECT_DOUBLE_EQ(s.max_neighbor_distance, 1.5);
  EXPECT_DOUBLE_EQ(s.edge_eigen_ratio, 4.0);
  EXPECT_DOUBLE_EQ(s.plane_tolerance, 0.15);
  EXPECT_DOUBLE_EQ(s.plane_min_aspect, 0.05);
  EXPECT_EQ(s.kernel, lidar::RobustKernel::kHuber);
  EXPECT_DOUBLE_EQ(s.min_weight, 0.2);
  EXPECT_DOUBLE_EQ(s.huber_delta, 0.05);
  EXPECT_DOUBLE_EQ(s.degeneracy_threshold, 50.0);
  EXPECT_DOUBLE_EQ(s.degeneracy_threshold_per_correspondence, 0.03);
  EXPECT_EQ(s.min_edge_features, 5);
  EXPECT_EQ(s.min_plane_features, 60);
  EXPECT_EQ(s.min_correspondences, 40);
  EXPECT_DOUBLE_EQ(c.keyframes.distance, 0.5);
  EXPECT_DOUBLE_EQ(c.keyframes.angle, 0.1);
}

TEST(OdometryConfigReader, EveryImuAndSmootherKeyReachesItsOwnFieldWithOneGravityForTheImuChain) {
  test::TempDir dir;
  const OdometryConfig c = load(
      dir,
      "odometry:\n  imu:\n    gyro_noise_density: 0.001\n    acc_noise_density: 0.01\n"
      "    gyro_bias_random_walk: 0.0001\n    acc_bias_random_walk: 0.002\n    integration_sigma: 0.0003\n"
      "    gravity: 9.79\n"
      "  smoother:\n    window: 6\n    prior_sigma_position: 0.02\n    prior_sigma_rotation: 0.03\n"
      "    prior_sigma_velocity: 0.5\n    prior_sigma_gyro_bias: 0.04\n    prior_sigma_acc_bias: 0.2\n"
      "    max_iterations: 8\n    max_velocity: 20\n    max_bias: 0.7\n");
  const imu::PreintegrationConfig& p = c.preintegration;
  EXPECT_DOUBLE_EQ(p.gyro_noise_density, 0.001);
  EXPECT_DOUBLE_EQ(p.acc_noise_density, 0.01);
  EXPECT_DOUBLE_EQ(p.gyro_bias_random_walk, 0.0001);
  EXPECT_DOUBLE_EQ(p.acc_bias_random_walk, 0.002);
  EXPECT_DOUBLE_EQ(p.integration_sigma, 0.0003);
  EXPECT_DOUBLE_EQ(p.gravity, 9.79);
  EXPECT_DOUBLE_EQ(c.propagator.gravity, 9.79);
  EXPECT_DOUBLE_EQ(c.initializer.gravity, 9.79);
  const backend::FixedLagSmootherConfig& s = c.smoother;
  EXPECT_EQ(s.window, 6);
  EXPECT_DOUBLE_EQ(s.prior_sigma_position, 0.02);
  EXPECT_DOUBLE_EQ(s.prior_sigma_rotation, 0.03);
  EXPECT_DOUBLE_EQ(s.prior_sigma_velocity, 0.5);
  EXPECT_DOUBLE_EQ(s.prior_sigma_gyro_bias, 0.04);
  EXPECT_DOUBLE_EQ(s.prior_sigma_acc_bias, 0.2);
  EXPECT_EQ(s.max_iterations, 8);
  EXPECT_DOUBLE_EQ(s.max_velocity, 20.0);
  EXPECT_DOUBLE_EQ(s.max_bias, 0.7);
}

}  // namespace
}  // namespace drover::io
