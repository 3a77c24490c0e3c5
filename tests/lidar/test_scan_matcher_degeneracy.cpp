// ScanMatcher's degeneracy test at different point densities: LIO-SAM's fixed eigenvalue threshold means less the
// more correspondences a sweep keeps (J^T J sums over them), so the matcher also holds the weakest eigenvalue
// against a share of the correspondences (ScanMatcherConfig::degeneracy_threshold_per_correspondence).
#include <gtest/gtest.h>

#include <cmath>

#include "lidar/scan_matcher.hpp"
#include "support/lidar_scenes.hpp"
#include "support/units.hpp"

namespace drover::lidar {
namespace {

using ::drover::test::kDeg;

// A corridor whose walls turn 8 deg away from its axis (0.6 m wide at one end, 3.4 m at the other, 20 m long): the
// axis is held by sin^2(8 deg) = 0.019 of each wall point's weight, about 1 % of the correspondences' in all.
const test::Scene kTapered = test::taperedCorridor(10.0, 2.0, -0.4, 2.0, 8.0 * kDeg);

MatchResult matchTapered(int scan_planes, int scan_edges, const ScanMatcherConfig& config) {
  const LocalMap map = test::buildMap(test::sampleMap(kTapered, 0.1));
  const Eigen::Isometry3d truth = test::poseRpy({0.2, 0.05, 0.02}, 0.3 * kDeg, -0.2 * kDeg, 1.0 * kDeg);
  const FeatureSet scan = test::sampleScan(kTapered, truth, scan_planes, scan_edges, 40.0, 5);
  return ScanMatcher(config).align(scan, map, Eigen::Isometry3d::Identity());
}

// The degenerate direction expressed in the world: its translation part along the corridor's axis.
double axisShare(const MatchResult& r) {
  EXPECT_EQ(r.degenerate_count, 1) << r.eigenvalues.transpose();
  if (r.degenerate_directions.empty()) return 0.0;
  return std::abs((r.T_world_lidar.linear() * r.degenerate_directions.front().head<3>()).x());
}

TEST(ScanMatcherDegeneracy, AWeaklyHeldCorridorAxisIsDegenerateWhateverTheScanDensity) {
  for (const int planes : {1500, 15000}) {
    const MatchResult r = matchTapered(planes, planes / 5, ScanMatcherConfig{});
    EXPECT_TRUE(r.degenerate) << planes << " planes: eigenvalues " << r.eigenvalues.transpose() << ", "
                              << r.edge_inliers + r.plane_inliers << " correspondences";
    EXPECT_GT(axisShare(r), 0.9) << planes << " planes";
  }
}

TEST(ScanMatcherDegeneracy, LioSamsFixedThresholdAloneMissesTheDenseScansWeakAxis) {
  ScanMatcherConfig lio_sam;
  lio_sam.degeneracy_threshold_per_correspondence = 0.0;
  const MatchResult sparse = matchTapered(1500, 300, lio_sam);
  EXPECT_TRUE(sparse.degenerate) << sparse.eigenvalues.transpose();
  const MatchResult dense = matchTapered(15000, 3000, lio_sam);
  // Ten times the correspondences, ten times the axis's eigenvalue: above 100, so no longer degenerate.
  EXPECT_FALSE(dense.degenerate) << dense.eigenvalues.transpose();
  EXPECT_GT(dense.eigenvalues.minCoeff(), 5.0 * sparse.eigenvalues.minCoeff());
}

TEST(ScanMatcherDegeneracy, ABoxRoomIsWellHeldAtAnyDensity) {
  const test::Scene room = test::boxRoom({-10.0, -6.0, -1.5}, {10.0, 6.0, 3.0});
  const LocalMap map = test::buildMap(test::sampleMap(room, 0.2));
  const Eigen::Isometry3d truth = test::poseRpy({0.3, 0.2, 0.05}, 1.0 * kDeg, 0.0, 5.0 * kDeg);
  for (const int planes : {1500, 15000}) {
    const MatchResult r = ScanMatcher().align(test::sampleScan(room, truth, planes, planes / 5, 100.0, 1), map,
                                              Eigen::Isometry3d::Identity());
    EXPECT_TRUE(r.converged) << r.reason;
    EXPECT_FALSE(r.degenerate) << planes << " planes: " << r.eigenvalues.transpose();
  }
}

TEST(ScanMatcherDegeneracy, TheThresholdIsTheHigherOfTheFixedAndThePerCorrespondenceOne) {
  ScanMatcherConfig c;
  c.degeneracy_threshold = 100.0;
  c.degeneracy_threshold_per_correspondence = 0.02;
  EXPECT_DOUBLE_EQ(c.degeneracyThreshold(2500), 100.0);
  EXPECT_DOUBLE_EQ(c.degeneracyThreshold(8000), 160.0);
  EXPECT_DOUBLE_EQ(c.degeneracyThreshold(-1), 100.0);
  c.degeneracy_threshold_per_correspondence = 0.0;
  EXPECT_DOUBLE_EQ(c.degeneracyThreshold(1000000), 100.0);
}

TEST(ScanMatcherDegeneracy, RejectsANegativeOrNonFinitePerCorrespondenceThreshold) {
  for (const double bad : {-0.01, std::nan("")}) {
    ScanMatcherConfig c;
    c.degeneracy_threshold_per_correspondence = bad;
    EXPECT_NE(c.validate().find("degeneracy_threshold_per_correspondence"), std::string::npos) << bad;
  }
}

}  // namespace
}  // namespace drover::lidar
