// ScanMatcher: LIO-SAM scan-to-map registration on exact synthetic geometry (support/lidar_scenes.hpp).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>

#include "geometry/se3.hpp"
#include "geometry/so3.hpp"
#include "lidar/scan_matcher.hpp"
#include "lidar/scan_matcher_residual.hpp"
#include "support/lidar_scenes.hpp"
#include "support/units.hpp"

namespace drover::lidar {
namespace {

using ::drover::test::kDeg;
using ::drover::test::boxRoom;
using ::drover::test::buildMap;
using ::drover::test::corridor;
using ::drover::test::poseRpy;
using ::drover::test::sampleMap;
using ::drover::test::sampleScan;
using ::drover::test::Scene;

double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}
double rotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return geometry::rotationAngle(a.linear().transpose() * b.linear()) / kDeg;
}

const Scene kRoom = boxRoom({-10.0, -6.0, -1.5}, {10.0, 6.0, 3.0});
const Eigen::Isometry3d kRoomOffset = poseRpy({0.3, 0.2, 0.05}, 1.0 * kDeg, 0.0, 5.0 * kDeg);

TEST(ScanMatcher, RecoversAKnownOffsetOnABoxRoomToAMillimetre) {
  const LocalMap map = buildMap(sampleMap(kRoom, 0.2));
  const FeatureSet scan = sampleScan(kRoom, kRoomOffset, 1500, 300, 100.0, 1);
  const MatchResult result = ScanMatcher().align(scan, map, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(result.converged) << result.reason;
  EXPECT_EQ(result.status, MatchStatus::kConverged);
  EXPECT_FALSE(result.degenerate) << result.eigenvalues.transpose();
  EXPECT_LE(translationError(result.T_world_lidar, kRoomOffset), 1e-3);
  EXPECT_LE(rotationErrorDeg(result.T_world_lidar, kRoomOffset), 0.01);
  EXPECT_GT(result.edge_inliers, 200);
  EXPECT_GT(result.plane_inliers, 1200);
  EXPECT_LT(result.fitness, 1e-3);
  EXPECT_GT(result.eigenvalues.minCoeff(), 100.0);
  // The covariance is the inverse of the information when nothing is degenerate.
  EXPECT_TRUE((result.covariance * result.information).isApprox(Matrix6d::Identity(), 1e-6));
  std::cout << "[ room ] " << result.reason << ", error " << translationError(result.T_world_lidar, kRoomOffset)
            << " m, " << rotationErrorDeg(result.T_world_lidar, kRoomOffset) << " deg\n";
}

TEST(ScanMatcher, HuberKernelRecoversTheSameOffset) {
  const LocalMap map = buildMap(sampleMap(kRoom, 0.2));
  const FeatureSet scan = sampleScan(kRoom, kRoomOffset, 1500, 300, 100.0, 2);
  ScanMatcherConfig config;
  config.kernel = RobustKernel::kHuber;
  const MatchResult result = ScanMatcher(config).align(scan, map, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(result.converged) << result.reason;
  EXPECT_LE(translationError(result.T_world_lidar, kRoomOffset), 1e-3);
  EXPECT_LE(rotationErrorDeg(result.T_world_lidar, kRoomOffset), 0.01);
}

TEST(ScanMatcher, ReportsACorridorAsDegenerateAlongItsAxisAndKeepsTheGuessAlongIt) {
  const Scene scene = corridor(100.0, 1.5, -1.2, 2.0);
  const LocalMap map = buildMap(sampleMap(scene, 0.2));
  const Eigen::Isometry3d truth = poseRpy({0.4, 0.1, 0.05}, 0.5 * kDeg, -0.3 * kDeg, 2.0 * kDeg);
  const Eigen::Isometry3d guess = poseRpy({-0.2, 0.0, 0.0}, 0.0, 0.0, 0.0);
  const FeatureSet scan = sampleScan(scene, truth, 1500, 300, 40.0, 3);
  const MatchResult result = ScanMatcher().align(scan, map, guess);
  EXPECT_TRUE(result.converged) << result.reason;
  ASSERT_TRUE(result.degenerate);
  ASSERT_EQ(result.degenerate_count, 1) << result.eigenvalues.transpose();
  // The degenerate direction is a translation along the corridor (world x), expressed in the lidar frame.
  const Vector6d& direction = result.degenerate_directions.front();
  EXPECT_LT(direction.tail<3>().norm(), 1e-6);
  EXPECT_GT(std::abs((result.T_world_lidar.linear() * direction.head<3>()).x()), 1.0 - 1e-9);
  // Zhang's remapping: no motion along the axis (truth is 0.6 m away along it); everything else is recovered.
  // Exactly none once the correspondences are right; the first iteration, at the guess, also has a few wrong
  // plane fits near the wall corners whose normals lean along x, so its null direction is off by a hair and
  // the guess's x is kept to ~20 um.
  EXPECT_NEAR(result.T_world_lidar.translation().x(), guess.translation().x(), 1e-4);
  EXPECT_NEAR(result.T_world_lidar.translation().y(), truth.translation().y(), 1e-3);
  EXPECT_NEAR(result.T_world_lidar.translation().z(), truth.translation().z(), 1e-3);
  EXPECT_LE(rotationErrorDeg(result.T_world_lidar, truth), 0.01);
  EXPECT_GE(result.covariance(0, 0) + result.covariance(1, 1) + result.covariance(2, 2), 1e5);
}

TEST(ScanMatcher, TooFewScanFeaturesReturnTheGuessNotConverged) {
  const LocalMap map = buildMap(sampleMap(kRoom, 0.2));
  const FeatureSet scan = sampleScan(kRoom, kRoomOffset, 60, 5, 100.0, 4);
  const Eigen::Isometry3d guess = poseRpy({0.1, 0.0, 0.0}, 0.0, 0.0, 0.1);
  const MatchResult result = ScanMatcher().align(scan, map, guess);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.status, MatchStatus::kTooFewFeatures);
  EXPECT_FALSE(result.reason.empty());
  EXPECT_TRUE(result.T_world_lidar.isApprox(guess, 0.0));
}

TEST(ScanMatcher, AScanFarFromTheMapFindsTooFewCorrespondencesAndReturnsTheGuess) {
  const LocalMap map = buildMap(sampleMap(kRoom, 0.2));
  const FeatureSet scan = sampleScan(kRoom, kRoomOffset, 1500, 300, 100.0, 5);
  const Eigen::Isometry3d guess = poseRpy({500.0, 0.0, 0.0}, 0.0, 0.0, 0.0);
  const MatchResult result = ScanMatcher().align(scan, map, guess);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.status, MatchStatus::kTooFewCorrespondences) << result.reason;
  EXPECT_TRUE(result.T_world_lidar.isApprox(guess, 0.0));
}

TEST(ScanMatcher, AnEmptyMapReturnsTheGuess) {
  const LocalMap map;
  const FeatureSet scan = sampleScan(kRoom, kRoomOffset, 200, 20, 100.0, 6);
  const MatchResult result = ScanMatcher().align(scan, map, Eigen::Isometry3d::Identity());
  EXPECT_EQ(result.status, MatchStatus::kEmptyMap);
  EXPECT_FALSE(result.converged);
}

TEST(ScanMatcher, ANonFiniteGuessThrows) {
  const LocalMap map = buildMap(sampleMap(kRoom, 0.2));
  const FeatureSet scan = sampleScan(kRoom, kRoomOffset, 200, 20, 100.0, 7);
  Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
  guess.translation().y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(ScanMatcher().align(scan, map, guess), std::invalid_argument);
}

TEST(ScanMatcher, ParallelAndSerialSearchGiveBitIdenticalResults) {
  const LocalMap map = buildMap(sampleMap(kRoom, 0.2));
  const FeatureSet scan = sampleScan(kRoom, kRoomOffset, 1500, 300, 100.0, 8);
  ScanMatcherConfig serial;
  serial.parallel = false;
  const MatchResult a = ScanMatcher().align(scan, map, Eigen::Isometry3d::Identity());
  const MatchResult b = ScanMatcher(serial).align(scan, map, Eigen::Isometry3d::Identity());
  EXPECT_EQ(a.T_world_lidar.matrix(), b.T_world_lidar.matrix());
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.hessian, b.hessian);
}

TEST(ScanMatcher, ReusingFitsWhoseNeighboursReturnGivesTheRecomputedResultToTheBit) {
  // Starting 0.3 m and 5 deg off, the first iterations change many points' neighbours and the last ones few: both
  // the reuse and its refusal are exercised.
  const LocalMap map = buildMap(sampleMap(kRoom, 0.2));
  const FeatureSet scan = sampleScan(kRoom, kRoomOffset, 1500, 300, 100.0, 9);
  ScanMatcherConfig recompute;
  recompute.reuse_fits = false;
  const MatchResult reused = ScanMatcher().align(scan, map, Eigen::Isometry3d::Identity());
  const MatchResult fresh = ScanMatcher(recompute).align(scan, map, Eigen::Isometry3d::Identity());
  EXPECT_EQ(reused.T_world_lidar.matrix(), fresh.T_world_lidar.matrix());
  EXPECT_EQ(reused.iterations, fresh.iterations);
  EXPECT_EQ(reused.hessian, fresh.hessian);
  EXPECT_EQ(reused.fitness, fresh.fitness);
  EXPECT_EQ(fresh.fits_reused, 0);
  ASSERT_GE(reused.iterations, 3);
  // Every point is fitted in the first iteration; afterwards most keep their neighbours, some do not.
  const int points = static_cast<int>(scan.edges.size() + scan.planes.size());
  EXPECT_GE(reused.fits_computed, points * 9 / 10);
  EXPECT_GT(reused.fits_computed, points * 11 / 10) << "no neighbours changed after the first iteration";
  EXPECT_GT(reused.fits_reused, points / 5) << reused.fits_computed << " computed, " << reused.iterations << " iterations";
  EXPECT_EQ(reused.fits_computed + reused.fits_reused, fresh.fits_computed);
}

TEST(ScanMatcher, RejectsAnInvalidConfig) {
  ScanMatcherConfig config;
  config.max_iterations = 0;
  EXPECT_THROW(ScanMatcher{config}, std::invalid_argument);
  config = {};
  config.plane_tolerance = -0.1;
  EXPECT_THROW(ScanMatcher{config}, std::invalid_argument);
  config = {};
  config.neighbors = 2;
  EXPECT_FALSE(config.validate().empty());
  config = {};
  config.plane_min_aspect = 1.0;
  EXPECT_NE(config.validate().find("plane_min_aspect"), std::string::npos);
}

// A ~2000-point scan against a ~50k-point local map: the figure is logged, not asserted.
TEST(ScanMatcher, LogsTheAlignTimeOfA2000PointScanOnA50kPointMap) {
  const Scene hall = boxRoom({-22.0, -15.0, -1.5}, {22.0, 15.0, 4.5});
  LocalMapConfig config;
  config.plane_leaf = 0.25;
  LocalMap map(config);
  map.addKeyframe(sampleMap(hall, 0.125), Eigen::Isometry3d::Identity());
  const auto build_start = std::chrono::steady_clock::now();
  map.build(Eigen::Vector3d::Zero());
  const double build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - build_start).count();
  const FeatureSet scan = sampleScan(hall, kRoomOffset, 1700, 300, 100.0, 9);
  const auto start = std::chrono::steady_clock::now();
  const MatchResult result = ScanMatcher().align(scan, map, Eigen::Isometry3d::Identity());
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(result.converged) << result.reason;
  std::cout << "[ timing ] align: " << scan.edges.size() + scan.planes.size() << " scan points, "
            << map.edgesWorld().size() + map.planesWorld().size() << " map points, " << result.iterations
            << " iterations, " << ms << " ms (" << ms / result.iterations << " ms/iteration); map build "
            << build_ms << " ms\n";
}

// The analytic Jacobians of scan_matcher_residual.hpp against central differences of r(T Exp(dxi)).
TEST(ScanMatcherResidual, AnalyticJacobiansMatchNumericalOnes) {
  const std::vector<Eigen::Vector3d> line = {{1, 2, 3}, {1.2, 2.1, 3.0}, {1.4, 2.2, 3.0}, {1.6, 2.3, 3.0},
                                             {1.8, 2.4, 3.0}};
  std::vector<Eigen::Vector3d> plane = {{0, 0, 1}, {1, 0, 1.1}, {0, 1, 0.9}, {1, 1, 1.0}, {0.5, 0.5, 1.0}};
  const detail::FeatureFit fits[] = {detail::fitLine(line.data(), 5, 3.0), detail::fitPlane(plane.data(), 5, 0.2)};
  const Eigen::Isometry3d T = poseRpy({0.5, -1.0, 2.0}, 0.3, -0.2, 1.1);
  const Eigen::Vector3d p(2.0, -1.0, 0.7);
  for (const auto& fit : fits) {
    ASSERT_TRUE(fit.valid);
    Eigen::Vector2d r;
    Eigen::Matrix<double, 2, 6> J;
    detail::residualAndJacobian(fit, T, p, r, J);
    for (int k = 0; k < 6; ++k) {
      const double h = 1e-6;
      Vector6d dxi = Vector6d::Zero();
      dxi(k) = h;
      Eigen::Vector2d rp, rm;
      Eigen::Matrix<double, 2, 6> unused;
      detail::residualAndJacobian(fit, T * geometry::expSE3(dxi), p, rp, unused);
      detail::residualAndJacobian(fit, T * geometry::expSE3(-dxi), p, rm, unused);
      EXPECT_TRUE(J.col(k).isApprox((rp - rm) / (2 * h), 1e-6) || (J.col(k) - (rp - rm) / (2 * h)).norm() < 1e-8)
          << "column " << k;
    }
  }
  // The residual norms are the distances: the line runs along (1, 0.5, 0) through (1.4, 2.2, 3), the plane is
  // tilted, so check against closed forms.
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 6> J;
  detail::residualAndJacobian(fits[0], Eigen::Isometry3d::Identity(), Eigen::Vector3d(1.4, 2.2, 4.0), r, J);
  EXPECT_NEAR(r.norm(), 1.0, 1e-12);
}

TEST(ScanMatcherResidual, RejectsScatteredLinesAndBentPlanes) {
  const std::vector<Eigen::Vector3d> blob = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  EXPECT_FALSE(detail::fitLine(blob.data(), 5, 3.0).valid);
  // Four points on z = 0 and one 0.6 m above: no plane fits all within 0.2 m.
  const std::vector<Eigen::Vector3d> bent = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.5, 0.6}};
  EXPECT_FALSE(detail::fitPlane(bent.data(), 5, 0.2).valid);
  const std::vector<Eigen::Vector3d> collinear = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}};
  EXPECT_FALSE(detail::fitPlane(collinear.data(), 5, 0.2).valid);
  EXPECT_TRUE(detail::fitLine(collinear.data(), 5, 3.0).valid);
}

// Five map points along one ring of a spinning lidar on flat ground (radius 8 m, 0.2 m apart, +-1 cm of range noise
// along a beam 15 deg down) span a strip whose width is the ring's curvature and the noise: a plane through them may
// turn about the ring, and it does (the fitted normal leans far from the vertical). Two rings 0.5 m apart fix the
// ground's normal.
TEST(ScanMatcherResidual, RefusesAPlaneAlongOneScanRingUnlessTheNeighboursSpanIt) {
  std::vector<Eigen::Vector3d> ring;
  const double noise[] = {0.01, -0.01, 0.0, 0.01, -0.01};
  for (int i = 0; i < 5; ++i) {
    const double a = (i - 2) * 0.2 / 8.0;  // [rad] 0.2 m apart on the 8 m ring
    // The beam meets the ground 15 deg down: range noise moves a point out by cos 15 and down by sin 15 of it.
    const double out = 8.0 + noise[i] * std::cos(0.2618), z = -noise[i] * std::sin(0.2618);
    ring.push_back(Eigen::Vector3d(out * std::cos(a), out * std::sin(a), z));
  }
  const detail::FeatureFit loose = detail::fitPlane(ring.data(), 5, 0.2, 0.0);
  ASSERT_TRUE(loose.valid) << "LIO-SAM's test takes it";
  const double lean_deg = std::acos(std::abs(loose.direction.z())) * 180.0 / M_PI;
  EXPECT_GT(lean_deg, 10.0) << "the normal the ring cannot fix";
  std::printf("one ring's plane leans %.1f deg from the vertical\n", lean_deg);
  constexpr double kAspect = 0.055;  // sqrt(3e-3): the value measured in bench/RESULTS.md
  EXPECT_FALSE(detail::fitPlane(ring.data(), 5, 0.2, kAspect).valid);
  std::vector<Eigen::Vector3d> two_rings;
  for (const double r : {8.0, 8.5})
    for (int i = -1; i <= 1; ++i)
      if (two_rings.size() < 5)
        two_rings.push_back(Eigen::Vector3d(r * std::cos(i * 0.025), r * std::sin(i * 0.025), 0.0));
  const detail::FeatureFit ground = detail::fitPlane(two_rings.data(), 5, 0.2, kAspect);
  ASSERT_TRUE(ground.valid);
  EXPECT_GT(std::abs(ground.direction.z()), std::cos(1.0 * M_PI / 180.0));
}

}  // namespace
}  // namespace drover::lidar
