// Lidar depth for features: exact planes, discontinuities, windows, and the simulator's ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <random>

#include "sim/camera_model.hpp"
#include "sim/lidar_model.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"
#include "visual/camera_model.hpp"
#include "visual/depth_association.hpp"
#include "visual/feature_tracker.hpp"

namespace drover::visual {
namespace {

constexpr Time kSecond = 1'000'000'000;

DepthAssociationConfig exactConfig() {
  DepthAssociationConfig c;
  c.voxel_size = 0;  // keep the synthetic points as they are
  return c;
}

// Points on the plane through `origin` spanned by unit vectors a, b, every `step` metres over [-half, half]^2.
std::vector<Eigen::Vector3d> planePoints(const Eigen::Vector3d& origin, const Eigen::Vector3d& a,
                                         const Eigen::Vector3d& b, double half, double step) {
  std::vector<Eigen::Vector3d> points;
  for (double u = -half; u <= half; u += step)
    for (double v = -half; v <= half; v += step) points.push_back(origin + u * a + v * b);
  return points;
}

std::vector<Eigen::Vector2d> randomFeatures(int n, double extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-extent, extent);
  std::vector<Eigen::Vector2d> f;
  for (int i = 0; i < n; ++i) f.emplace_back(u(rng), u(rng));
  return f;
}

TEST(DepthAssociation, AFrontoParallelWallGivesItsExactDistance) {
  DepthAssociator associator(exactConfig());
  associator.addSweep(0, planePoints({0, 0, 5}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 8, 0.1));
  const auto features = randomFeatures(200, 0.6, 1);
  const DepthAssociationResult r = associator.associate(0, Eigen::Isometry3d::Identity(), features);
  EXPECT_EQ(r.associated, 200);
  for (const FeatureDepth& f : r.features) {
    ASSERT_EQ(f.status, DepthStatus::kOk);
    EXPECT_NEAR(f.depth, 5.0, 1e-5);
  }
}

// A loop correction moves the LIS's world by T_new_old: the stored sweep moves with it, so a camera pose given in the
// corrected world finds the wall at its true distance again (without the reanchor: 1 m off, or nothing).
TEST(DepthAssociation, AReanchoredSweepAgreesWithCameraPosesInTheCorrectedWorld) {
  DepthAssociator associator(exactConfig());
  associator.addSweep(0, planePoints({0, 0, 5}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 8, 0.1));
  Eigen::Isometry3d T_new_old = Eigen::Isometry3d::Identity();
  T_new_old.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T_new_old.translation() = Eigen::Vector3d(0.5, -0.3, 1.0);
  const auto features = randomFeatures(100, 0.3, 2);
  const Eigen::Isometry3d T_new_cam = T_new_old;  // the same camera (identity in the old world), corrected
  const DepthAssociationResult stale = associator.associate(0, T_new_cam, features);
  associator.reanchor(T_new_old);
  const DepthAssociationResult r = associator.associate(0, T_new_cam, features);
  EXPECT_EQ(r.associated, 100);
  for (const FeatureDepth& f : r.features) EXPECT_NEAR(f.depth, 5.0, 1e-5);
  int stale_right = 0;
  for (const FeatureDepth& f : stale.features)
    stale_right += f.status == DepthStatus::kOk && std::abs(f.depth - 5.0) < 0.05;
  EXPECT_EQ(stale_right, 0);
}

TEST(DepthAssociation, ATiltedWallSeenFromAMovedCameraGivesTheRayPlaneIntersection) {
  DepthAssociator associator(exactConfig());
  // Wall through (2, 1, 9) with normal n, in the world; camera rotated and moved.
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.2, -1).normalized();
  const Eigen::Vector3d a = n.cross(Eigen::Vector3d::UnitY()).normalized(), b = n.cross(a);
  const Eigen::Vector3d wall_origin(2, 1, 9);
  associator.addSweep(0, planePoints(wall_origin, a, b, 12, 0.1));
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.1, 1, 0.2).normalized()).toRotationMatrix();
  T_world_cam.translation() = Eigen::Vector3d(1.5, 0.5, 1.0);
  const auto features = randomFeatures(200, 0.5, 2);
  const DepthAssociationResult r = associator.associate(0, T_world_cam, features);
  EXPECT_GT(r.associated, 190);
  for (std::size_t i = 0; i < features.size(); ++i) {
    if (r.features[i].status != DepthStatus::kOk) continue;
    // Exact: ray o + s R (x, y, 1) meets n . (p - wall_origin) = 0.
    const Eigen::Vector3d d = T_world_cam.linear() * Eigen::Vector3d(features[i].x(), features[i].y(), 1);
    const double z = n.dot(wall_origin - T_world_cam.translation()) / n.dot(d);
    EXPECT_NEAR(r.features[i].depth, z, 1e-4 * z);
  }
}

TEST(DepthAssociation, RejectsFeaturesOnADepthDiscontinuity) {
  // A board at 3 m covers x < 0 (camera frame), a wall at 10 m is behind everything.
  DepthAssociator associator(exactConfig());
  // The board is sampled densely (0.38 deg < the 0.5 deg grid) so that no background point shows through it.
  auto points = planePoints({-4, 0, 3}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 4, 0.02);
  const auto wall = planePoints({0, 0, 10}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 20, 0.2);
  points.insert(points.end(), wall.begin(), wall.end());
  associator.addSweep(0, points);
  std::vector<Eigen::Vector2d> features;
  for (double x = -0.5; x <= 0.5; x += 0.002) features.emplace_back(x, 0.05);
  const DepthAssociationResult r = associator.associate(0, Eigen::Isometry3d::Identity(), features);
  EXPECT_GT(r.rejected_discontinuity, 0);
  for (std::size_t i = 0; i < features.size(); ++i) {
    const double x = features[i].x();
    const FeatureDepth& f = r.features[i];
    if (std::abs(x) < 0.01) continue;  // within a grid cell of the edge: either side or rejected
    if (f.status != DepthStatus::kOk) {
      EXPECT_EQ(f.status, DepthStatus::kDiscontinuity) << "x = " << x;
      EXPECT_LT(std::abs(x), 0.06) << "only rays within a few cells of the edge are rejected";
      continue;
    }
    EXPECT_NEAR(f.depth, x < 0 ? 3.0 : 10.0, 1e-4) << "x = " << x << ": never a depth between the two surfaces";
  }
}

TEST(DepthAssociation, UsesOnlySweepsInsideTheWindowAndTheDepthRange) {
  DepthAssociationConfig config = exactConfig();
  config.window_s = 1.0;
  DepthAssociator associator(config);
  associator.addSweep(0, planePoints({0, 0, 4}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 6, 0.1));
  const auto features = randomFeatures(20, 0.5, 3);
  EXPECT_EQ(associator.associate(kSecond / 2, Eigen::Isometry3d::Identity(), features).associated, 20);
  EXPECT_EQ(associator.associate(2 * kSecond, Eigen::Isometry3d::Identity(), features).associated, 0)
      << "the sweep is older than the window";
  associator.addSweep(3 * kSecond,
                      planePoints({0, 0, 0.3}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 1, 0.01));
  EXPECT_EQ(associator.sweepCount(), 1u);
  const DepthAssociationResult r = associator.associate(3 * kSecond, Eigen::Isometry3d::Identity(), features);
  EXPECT_EQ(r.rejected_range, 20) << "0.3 m is below min_depth";
  EXPECT_THROW(associator.addSweep(kSecond, {}), std::invalid_argument);
  config.max_depth_spread = 0;
  EXPECT_THROW(DepthAssociator{config}, std::invalid_argument);
}

TEST(DepthAssociation, WithoutLidarPointsNoFeatureGetsADepth) {
  const DepthAssociator associator(DepthAssociationConfig{});
  const DepthAssociationResult r = associator.associate(0, Eigen::Isometry3d::Identity(), randomFeatures(5, 0.3, 4));
  EXPECT_EQ(r.no_neighbours, 5);
  EXPECT_EQ(r.associated, 0);
}

// The simulator's `straight` course, 6 s: VLP-16 sweeps deskewed with the ground-truth trajectory (so the test
// measures the association, not the odometry), Shi-Tomasi corners on the rendered images, and the true depth by
// casting each feature's ray into the simulated world. Figure: median relative depth error <= 2 %.
TEST(DepthAssociation, OnTheSimulatorCourseMedianRelativeErrorIsBelowTwoPercent) {
  sim::ScenarioOptions options;
  options.duration_s = 6.0;
  const sim::Scenario scenario = sim::makeScenario("straight", options);
  const sim::SimulatorConfig config = sim::SimulatorConfig::defaults();
  const sim::SplineTrajectory& trajectory = *scenario.trajectory;
  DepthAssociator associator(DepthAssociationConfig{});
  const sim::CameraRenderer renderer(config.camera);
  const CameraModel camera(config.camera.intrinsics);
  std::vector<double> relative_errors;
  int features_total = 0;
  std::uint64_t sweep_index = 0;
  Time next_sweep = 0;
  for (Time t_frame = 2 * kSecond; t_frame <= 5 * kSecond; t_frame += kSecond / 2) {
    while (next_sweep + kSecond / 10 <= t_frame) {  // sweeps that ended before the frame
      const LidarScan scan = sim::simulateSweep(scenario.world, trajectory, config.T_imu_lidar, next_sweep,
                                                config.lidar, 7, sweep_index++);
      std::vector<Eigen::Vector3d> points_world;
      for (const LidarPoint& p : scan.points) {
        const Time t_point = scan.t + static_cast<Time>(std::llround(p.time_offset * 1e9));
        points_world.push_back(trajectory.pose(t_point) * config.T_imu_lidar * Eigen::Vector3d(p.x, p.y, p.z));
      }
      associator.addSweep(scan.t, points_world);
      next_sweep += kSecond / 10;
    }
    const Eigen::Isometry3d T_world_cam = trajectory.pose(t_frame) * config.T_imu_cam;
    const CameraFrame frame =
        renderer.render(scenario.world, trajectory, config.T_imu_cam, scenario.illumination, t_frame, 1, 0);
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(imageView(frame.image), corners, 150, 0.01, 20);
    std::vector<Eigen::Vector2d> normalized;
    for (const cv::Point2f& c : corners) normalized.push_back(*camera.undistort({c.x, c.y}));
    const DepthAssociationResult r = associator.associate(t_frame, T_world_cam, normalized);
    features_total += static_cast<int>(normalized.size());
    for (std::size_t i = 0; i < normalized.size(); ++i) {
      if (r.features[i].status != DepthStatus::kOk) continue;
      const Eigen::Vector3d ray_cam = Eigen::Vector3d(normalized[i].x(), normalized[i].y(), 1).normalized();
      const auto hit = scenario.world.intersect({T_world_cam.translation(), T_world_cam.linear() * ray_cam});
      if (!hit) continue;  // sky: no true depth
      const double true_depth = hit->distance * ray_cam.z();
      relative_errors.push_back(std::abs(r.features[i].depth - true_depth) / true_depth);
    }
  }
  ASSERT_GT(relative_errors.size(), 100u);
  std::sort(relative_errors.begin(), relative_errors.end());
  const double median = relative_errors[relative_errors.size() / 2];
  const double p90 = relative_errors[relative_errors.size() * 9 / 10];
  std::printf("sim straight: %zu of %d features associated, median relative error %.4f, p90 %.4f\n",
              relative_errors.size(), features_total, median, p90);
  EXPECT_LE(median, 0.02);
  EXPECT_GT(static_cast<double>(relative_errors.size()) / features_total, 0.3) << "association rate";
}

}  // namespace
}  // namespace drover::visual
