// LocalMap: which keyframes are assembled, where their points land, and how many there are.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <stdexcept>

#include "lidar/local_map.hpp"

namespace drover::lidar {
namespace {

Eigen::Isometry3d at(double x, double y = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

// A 2 m x 2 m patch of plane points on z = 0 and an edge line along x, in the lidar frame, `n` points each.
FeatureSet patch(double t_seconds, int n = 400, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  FeatureSet f;
  f.t = fromSeconds(t_seconds);
  for (int i = 0; i < n; ++i) {
    f.planes.emplace_back(unit(rng), unit(rng), 0.0f);
    f.edges.emplace_back(unit(rng), 0.0f, 1.0f);
    f.full.emplace_back(unit(rng), unit(rng), 0.5f);
  }
  return f;
}

bool anyPointNear(const PointCloud& cloud, double x, double radius = 2.0) {
  return std::any_of(cloud.begin(), cloud.end(),
                     [&](const Eigen::Vector3f& p) { return std::abs(p.x() - x) < radius; });
}

TEST(LocalMap, ExcludesFarKeyframesAndIncludesRecentOnesWhereverTheyAre) {
  LocalMapConfig config;
  config.keyframe_density = 0.0;
  config.recent_window = 1.5;  // [s]
  LocalMap map(config);
  map.addKeyframe(patch(0.0), at(0.0));    // near the centre
  map.addKeyframe(patch(10.0), at(200.0));  // far and old: excluded
  map.addKeyframe(patch(20.0), at(40.0));   // near (inside 50 m)
  map.addKeyframe(patch(20.5), at(300.0));  // far but within 1.5 s of the newest: included
  map.addKeyframe(patch(21.0), at(500.0));  // the newest, far: included
  const LocalMapBuild build = map.build(Eigen::Vector3d::Zero());
  EXPECT_EQ(build.keyframes, (std::vector<std::size_t>{0, 2, 3, 4}));
  EXPECT_EQ(map.assembledKeyframes(), build.keyframes);
  for (double x : {0.0, 40.0, 300.0, 500.0}) {
    EXPECT_TRUE(anyPointNear(map.planesWorld(), x)) << x;
    EXPECT_TRUE(anyPointNear(map.edgesWorld(), x)) << x;
  }
  EXPECT_FALSE(anyPointNear(map.planesWorld(), 200.0));
  EXPECT_FALSE(anyPointNear(map.edgesWorld(), 200.0));
}

TEST(LocalMap, RecentCountIncludesTheNewestKeyframes) {
  LocalMapConfig config;
  config.recent_window = 0.0;
  config.recent_count = 2;
  LocalMap map(config);
  for (int i = 0; i < 5; ++i) map.addKeyframe(patch(i), at(100.0 * i));
  EXPECT_EQ(map.build(Eigen::Vector3d::Zero()).keyframes, (std::vector<std::size_t>{0, 3, 4}));
}

TEST(LocalMap, KeyframeDensityKeepsTheNewestKeyframePerCell) {
  LocalMapConfig config;
  config.recent_window = 0.0;
  config.keyframe_density = 2.0;  // [m]
  LocalMap map(config);
  for (int i = 0; i < 4; ++i) map.addKeyframe(patch(i), at(0.1 + 0.5 * i));  // x in [0.1, 1.6]: one cell
  map.addKeyframe(patch(4.0), at(2.5));                                     // the next cell
  EXPECT_EQ(map.build(Eigen::Vector3d::Zero()).keyframes, (std::vector<std::size_t>{3, 4}));
}

TEST(LocalMap, UpdatePoseMovesTheAssembledPoints) {
  LocalMap map;
  map.addKeyframe(patch(0.0), at(0.0));
  map.build(Eigen::Vector3d::Zero());
  const PointCloud before = map.planesWorld();
  // 4 m is a whole number of plane voxels (0.4 m), so the world voxel grid slices the moved points alike.
  map.updatePose(0, at(0.0, 4.0));
  const LocalMapBuild build = map.build(Eigen::Vector3d::Zero());
  EXPECT_FALSE(build.reused);
  EXPECT_EQ(build.transformed, 1u);
  EXPECT_TRUE(map.keyframe(0).T_world_lidar.isApprox(at(0.0, 4.0)));
  ASSERT_EQ(map.planesWorld().size(), before.size());
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_TRUE(map.planesWorld()[i].isApprox(before[i] + Eigen::Vector3f(0.0f, 4.0f, 0.0f), 1e-6f));
  }
}

TEST(LocalMap, ReusesCachedKeyframesAndSkipsAnUnchangedRebuild) {
  LocalMap map;
  map.addKeyframe(patch(0.0), at(0.0));
  map.addKeyframe(patch(1.0), at(3.0));
  EXPECT_EQ(map.build(Eigen::Vector3d::Zero()).transformed, 2u);
  const LocalMapBuild same = map.build(Eigen::Vector3d(1.0, 0.0, 0.0));
  EXPECT_TRUE(same.reused);
  EXPECT_EQ(same.transformed, 0u);
  map.addKeyframe(patch(2.0), at(6.0));
  const LocalMapBuild grown = map.build(Eigen::Vector3d::Zero());
  EXPECT_FALSE(grown.reused);
  EXPECT_EQ(grown.transformed, 1u);  // only the new keyframe
  EXPECT_EQ(grown.keyframes.size(), 3u);
}

// The live loop thread's keyframe store takes the LIS's keyframe clouds as they are: the same memory, the same map.
TEST(LocalMap, ASharedKeyframeIsTheOtherMapsCloudsNotACopy) {
  LocalMap lis, loop;
  lis.addKeyframe(patch(0.0, 5000, 3), at(0.0));
  loop.addSharedKeyframe(lis.keyframe(0).shared, at(0.0));
  EXPECT_EQ(loop.keyframe(0).shared.get(), lis.keyframe(0).shared.get());
  EXPECT_EQ(lis.keyframe(0).shared.use_count(), 2);
  lis.build(Eigen::Vector3d::Zero());
  loop.build(Eigen::Vector3d::Zero());
  EXPECT_EQ(loop.planesWorld(), lis.planesWorld());
  EXPECT_EQ(loop.edgesWorld(), lis.edgesWorld());
  EXPECT_THROW(loop.addSharedKeyframe(nullptr, at(0.0)), std::invalid_argument);
}

TEST(LocalMap, VoxelDownsamplingBoundsThePointCount) {
  LocalMap map;  // planes 0.4 m, edges 0.2 m
  // Twenty keyframes of 5000 points each at the same place: the 2 m x 2 m patch holds at most 6 x 6 plane
  // voxels and the 2 m edge line at most 11 edge voxels, however many keyframes overlap.
  for (int i = 0; i < 20; ++i) map.addKeyframe(patch(0.1 * i, 5000, 10 + i), at(0.0));
  EXPECT_LE(map.keyframe(0).features().planes.size(), 36u);
  EXPECT_LE(map.keyframe(0).features().edges.size(), 11u);
  const LocalMapBuild build = map.build(Eigen::Vector3d::Zero());
  EXPECT_EQ(build.keyframes.size(), 20u);
  EXPECT_LE(build.plane_points, 36u);
  EXPECT_GE(build.plane_points, 25u);
  EXPECT_LE(build.edge_points, 11u);
  // Every stored centroid stays on the patch plane.
  for (const auto& p : map.planesWorld()) EXPECT_NEAR(p.z(), 0.0f, 1e-6f);
}

TEST(LocalMap, NearestNeighboursComeSortedFromTheAssembledClouds) {
  LocalMapConfig config;
  config.plane_leaf = 0.01;
  LocalMap map(config);
  FeatureSet f;
  for (int i = 0; i < 10; ++i) f.planes.emplace_back(static_cast<float>(i), 0.0f, 0.0f);
  f.edges.emplace_back(0.0f, 0.0f, 5.0f);
  map.addKeyframe(f, at(100.0));
  map.build(Eigen::Vector3d(100.0, 0.0, 0.0));
  std::uint32_t idx[3];
  float sq[3];
  ASSERT_EQ(map.nearestPlanes(Eigen::Vector3f(103.2f, 0.0f, 0.0f), idx, sq), 3u);
  EXPECT_FLOAT_EQ(map.planesWorld()[idx[0]].x(), 103.0f);
  EXPECT_NEAR(sq[0], 0.04f, 1e-4f);
  EXPECT_FLOAT_EQ(map.planesWorld()[idx[1]].x(), 104.0f);
  EXPECT_FLOAT_EQ(map.planesWorld()[idx[2]].x(), 102.0f);
  // Fewer points than asked for: returns how many there are.
  EXPECT_EQ(map.nearestEdges(Eigen::Vector3f::Zero(), idx, sq), 1u);
}

TEST(LocalMap, FullCloudOfChosenKeyframesIsInTheWorldFrame) {
  LocalMap map;
  map.addKeyframe(patch(0.0, 100), at(10.0));
  map.addKeyframe(patch(1.0, 100), at(-10.0));
  const std::size_t both[] = {0, 1};
  const PointCloud full = map.fullCloudWorld(both);
  EXPECT_EQ(full.size(), 200u);
  EXPECT_TRUE(anyPointNear(full, 10.0) && anyPointNear(full, -10.0));
  const std::size_t first[] = {0};
  for (const auto& p : map.fullCloudWorld(first, 0.5f)) EXPECT_NEAR(p.x(), 10.0f, 1.0f);
  EXPECT_LE(map.fullCloudWorld(first, 0.5f).size(), 36u);
  const std::size_t bad[] = {7};
  EXPECT_THROW(map.fullCloudWorld(bad), std::invalid_argument);
}

TEST(LocalMap, AnEmptyMapBuildsEmptyClouds) {
  LocalMap map;
  const LocalMapBuild build = map.build(Eigen::Vector3d::Zero());
  EXPECT_TRUE(build.keyframes.empty());
  EXPECT_TRUE(map.edgesWorld().empty() && map.planesWorld().empty());
  std::uint32_t idx[5];
  float sq[5];
  EXPECT_EQ(map.nearestPlanes(Eigen::Vector3f::Zero(), idx, sq), 0u);
}

TEST(LocalMap, RejectsBadConfigIndicesAndPoses) {
  LocalMapConfig config;
  config.surrounding_radius = 0.0;
  EXPECT_THROW(LocalMap{config}, std::invalid_argument);
  config = {};
  config.plane_leaf = -0.4;
  EXPECT_THROW(LocalMap{config}, std::invalid_argument);
  config = {};
  config.recent_count = -1;
  EXPECT_FALSE(config.validate().empty());
  LocalMap map;
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().z() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(map.addKeyframe(patch(0.0), bad), std::invalid_argument);
  map.addKeyframe(patch(0.0), at(0.0));
  EXPECT_THROW(map.updatePose(1, at(1.0)), std::invalid_argument);
  EXPECT_THROW(map.updatePose(0, bad), std::invalid_argument);
  EXPECT_THROW(map.keyframe(3), std::invalid_argument);
  EXPECT_THROW(map.retire(1), std::invalid_argument);
  EXPECT_THROW(map.supersededBy(1), std::invalid_argument);
  EXPECT_EQ(map.poses().size(), 1u);
  config = {};
  config.retire_radius = -1.0;
  EXPECT_NE(config.validate().find("retire_radius"), std::string::npos);
  config = {};
  config.retire_age = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(config.validate().find("retire_age"), std::string::npos);
}

// A corridor driven twice, keyframes every metre: the first pass at t = 0..9 s, the second at t = 100..109 s,
// 0.3 m to the side and half a metre along. Each second-pass keyframe supersedes the first-pass ones within 1 m
// that are at least 60 s older; none of its own pass.
TEST(LocalMap, AKeyframeSupersedesTheOlderPassesKeyframesWithinTheRetireRadius) {
  LocalMapConfig config;
  config.retire_radius = 1.0;  // [m]
  config.retire_age = 60.0;    // [s]
  LocalMap map(config);
  for (int i = 0; i < 10; ++i) map.addKeyframe(patch(i), at(i));
  for (int i = 0; i < 10; ++i) map.addKeyframe(patch(100.0 + i), at(i + 0.5, 0.3));
  // Keyframe 12 at (2.5, 0.3): first-pass keyframes 2 (0.58 m) and 3 (0.58 m); 1 and 4 are 1.54 m away.
  EXPECT_EQ(map.supersededBy(12), (std::vector<std::size_t>{2, 3}));
  EXPECT_TRUE(map.supersededBy(5).empty()) << "its own pass is never older by 60 s";
  config.retire_radius = 0.0;
  LocalMap keeps_all(config);
  for (int i = 0; i < 2; ++i) keeps_all.addKeyframe(patch(100.0 * i), at(0.0));
  EXPECT_TRUE(keeps_all.supersededBy(1).empty()) << "retire_radius 0 keeps every keyframe";
}

TEST(LocalMap, ARetiredKeyframeLosesItsCloudsKeepsItsPoseAndLeavesTheLocalMap) {
  LocalMapConfig config;
  config.recent_window = 0.0;
  config.keyframe_density = 0.0;
  LocalMap map(config);
  map.addKeyframe(patch(0.0), at(0.0));
  map.addKeyframe(patch(100.0, 400, 2), at(0.4));
  EXPECT_EQ(map.build(Eigen::Vector3d::Zero()).keyframes, (std::vector<std::size_t>{0, 1}));
  const std::size_t cached = map.cacheBytes();
  EXPECT_GT(cached, 0u);
  const std::shared_ptr<const FeatureSet> before = map.keyframe(0).shared;
  map.retire(0);
  map.retire(0);  // twice: harmless
  EXPECT_EQ(map.retiredCount(), 1u);
  EXPECT_TRUE(map.keyframe(0).retired);
  EXPECT_TRUE(map.keyframe(0).features().edges.empty() && map.keyframe(0).features().planes.empty() &&
              map.keyframe(0).features().full.empty());
  EXPECT_EQ(before.use_count(), 1) << "the map no longer holds the old clouds";
  EXPECT_EQ(map.keyframe(0).t, fromSeconds(0.0));
  EXPECT_TRUE(map.keyframe(0).T_world_lidar.isApprox(at(0.0)));
  EXPECT_LT(map.cacheBytes(), cached);
  EXPECT_EQ(map.build(Eigen::Vector3d::Zero()).keyframes, (std::vector<std::size_t>{1}));
  EXPECT_TRUE(map.supersededBy(1).empty()) << "a retired keyframe is not superseded again";
}

}  // namespace
}  // namespace drover::lidar
